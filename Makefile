# Two commands on a fresh machine:  `make reproduce`  and  `make test`.
# Both create .venv from environment.lock (hashed, PyPI only) on first use.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
JOBS   ?= 2
# what `make reproduce` / `make recover` build, and extra Snakemake options (last on the line, e.g.
# SNAKEMAKE_ARGS="--configfile config/quick.yaml"); REPORT= (empty) skips the HTML report
TARGETS ?= all archive
SNAKEMAKE_ARGS ?=
REPORT ?= results/report.html

.PHONY: reproduce test quick report archive lock clean-results unlock recover

$(STAMP): environment.lock pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --require-hashes --no-deps -r environment.lock
	$(BIN)/pip install --quiet --no-deps --no-build-isolation -e .
	$(BIN)/python -m ipykernel install --sys-prefix --name python3 >/dev/null
	@# numba cache (the package's __pycache__): one tiny quartic chart compiles the CPU engine once
	@# here, so the first escape_chart of a later process loads it (benchmarks/bench_cold_start.py)
	$(BIN)/python -c "import numpy as np, safebasins.numerics as nu; q = np.linspace(-0.5, 0.5, 2); \
	nu.escape_chart(q, q, F=0.01, Omega=0.9, Psi=np.pi, xi_max=(0.18,), cycles=2)"
	touch $(STAMP)

## Full reproduction at paper resolution: every dataset, figure, the archive and the HTML report.
reproduce: $(STAMP)
	@$(BIN)/snakemake -j$(JOBS) --rerun-incomplete $(TARGETS) $(SNAKEMAKE_ARGS) || { \
	  if [ -n "$$(ls -A .snakemake/locks 2>/dev/null; ls -A .snakemake/incomplete 2>/dev/null)" ]; then \
	    echo "A killed run left Snakemake's lock or incomplete-file markers in .snakemake/. Run:  make recover"; fi; \
	  case "$(SNAKEMAKE_ARGS)" in *configfile*) \
	    echo "If Snakemake said 'Config file is not valid JSON or YAML' (no file, no line):" \
	         "$(BIN)/safebasins check-config FILE names both and checks the file as the pipeline will.";; esac; \
	  exit 1; }
	$(if $(REPORT),$(BIN)/snakemake -j$(JOBS) --report $(REPORT) $(SNAKEMAKE_ARGS))

## After a killed run (the next run stops with a LockException or an IncompleteFilesException):
## release the stale lock, then `make reproduce` (--rerun-incomplete redoes the interrupted jobs).
## Nothing finished is deleted. Only while no other Snakemake runs in this directory.
recover: $(STAMP)
	$(BIN)/snakemake --unlock $(SNAKEMAKE_ARGS)
	$(MAKE) -f $(firstword $(MAKEFILE_LIST)) reproduce

## After a killed run: release Snakemake's lock on the working directory (nothing is deleted).
unlock: $(STAMP)
	$(BIN)/snakemake --unlock

## Test suite (theory, numerics, config validation, one quick end-to-end pipeline run).
test: $(STAMP)
	$(BIN)/python -m pytest -n $(JOBS) --dist loadfile

## Lint, types and layers (pyproject's [tool.ruff], [tool.mypy], [tool.importlinter];
## docs/contracts.md): ruff over src and tests, mypy over src/safebasins (strict on wells,
## numerics, theory), the layer contract.
.PHONY: lint
lint: $(STAMP)
	$(BIN)/ruff check src tests
	$(BIN)/mypy
	$(BIN)/lint-imports

## The whole DAG at coarse resolution (a few minutes).
quick: $(STAMP)
	$(BIN)/snakemake -j$(JOBS) --configfile config/quick.yaml --rerun-incomplete all

## Regenerate environment.lock from requirements/requirements.in (needs `uv`).
lock:
	uv pip compile --generate-hashes --python-version 3.11 --python-platform x86_64-manylinux_2_28 requirements/requirements.in -o environment.lock

## Real single-node SLURM run (needs root: installs slurm-wlm + munge when missing): the quick
## datasets through workflow/profiles/slurm must equal a local -j2 run (tests/cluster/).
.PHONY: test-cluster
test-cluster: $(STAMP)
	tests/cluster/run_cluster_check.sh

## Speed benchmarks (not run by CI): rerun them and rewrite the README's benchmarks table
## (quick variants, ~2 min on 2 cores; BENCH_FLAGS=--full for the paper-size ones).
.PHONY: benchmarks
benchmarks: $(STAMP)
	$(BIN)/python scripts/update_benchmarks.py $(BENCH_FLAGS)

## The documentation site (docs/_build/html): Sphinx + MyST-NB, tutorials executed on every
## build, every warning an error. Open docs/_build/html/index.html (docs/index.md says more).
.PHONY: docs
docs: $(STAMP)
	$(BIN)/sphinx-build -E -W --keep-going -b html -d docs/_build/doctrees docs docs/_build/html
