"""A run's plan: every experiment of a validated config with its resolved parameters, datasets,
chart tasks and figure -- what the Snakefile, the rule scripts, the notebook generator, the
report and the cost estimate read.

    from safebasins.pipeline.plan import plan
    run = plan(config)                    # validates (filling defaults), then resolves
    run.experiments["fig13"].params       # = results/params/fig13.yaml
    run.product("results/data/numeric/chart_fig13.nc").build(...)
"""
from __future__ import annotations

import os
import zlib
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from safebasins import wells
from safebasins.pipeline import values
from safebasins.pipeline.config import experiment_blocks, load_yaml, merge_config, validate_config
from safebasins.pipeline.validation import ConfigError, fail
from safebasins.pipeline.registry import (KINDS, PARAMS_DIR, PARTS_DIR, Experiment, FigureSpec, Product,
                                          ResolveContext, params_path)

if TYPE_CHECKING:
    from safebasins.pipeline.catalog import Declaration
    from safebasins.pipeline.registry import Kind, Params

__all__ = ["Plan", "plan", "tile_path", "load_config"]


def tile_path(experiment: str, task: int, tile: int, tiles: int) -> str:
    return f"{PARTS_DIR}/{experiment}/task{task}_tile{tile}of{tiles}.nc"


def _seed_offset(name: str, decl: Declaration | None) -> int:
    if decl is not None:
        return decl.seed_offset
    # experiments declared in the config get a stable offset of their own (never a catalog one)
    return 1_000_000 + 1000 * (zlib.crc32(name.encode()) % 100_000)


def _figure(name: str, kind: Kind, params: Params, decl: Declaration | None) -> FigureSpec | None:
    if kind.builder is None:
        return None
    if decl is not None:
        return FigureSpec(name=name, stem=decl.stem, builder=kind.builder, inputs=kind.figure_inputs(name, params),
                          options=dict(decl.options), caption=decl.caption, look=decl.look, label=decl.label,
                          category=decl.category, packaged=True)
    caption, look = kind.default_figure_text(name, params)
    return FigureSpec(name=name, stem=name, builder=kind.builder, inputs=kind.figure_inputs(name, params),
                      options={}, caption=caption, look=look, label=params["title"], category="Experiments",
                      packaged=False)


def _check_compiled(exp: Experiment, spec: dict[str, Any]) -> None:
    """The well of an experiment with numerics has a compiled form (a polynomial up to the degree
    of wells.compiled.POLY_DEGREES): refused here, naming the key, not when its job runs."""
    if spec["name"] == "polynomial" and exp.kind.cost(exp.params) > 0:
        try:
            wells.from_spec(spec).compiled  # noqa: B018  (building the compiled form is the check)
        except ValueError as exc:
            fail(f"{exp.key}.well", f"the numerics of this experiment cannot integrate this well: {exc}")


class Plan:
    """Experiments of one validated config, in catalog order then config order."""

    def __init__(self, config: dict[str, Any]) -> None:
        self.config = config
        num = config["numerics"]
        self.threads = int(num["threads"])
        #: tile jobs per chart task (rule chart_tile); 0: none, the dataset that reads an experiment's
        #: charts integrates its tasks in its own job (no per-task process start-up)
        self.tiles = int(num["tiles"])
        self.experiments: dict[str, Experiment] = {}
        self._products: dict[str, tuple[Experiment, Product]] = {}
        for name, kind_name, key, blk, decl in experiment_blocks(config):
            kind = KINDS[kind_name]
            well = wells.spec_of(blk["well"])
            ctx = ResolveContext(fourier=config["fourier"] if well["name"] == "quartic" else "exact", well=well,
                                 steps_per_cycle=int(num["steps_per_cycle"]),
                                 seed=int(config["seed"]) + _seed_offset(name, decl))
            title = decl.title if decl is not None else blk.get("title", f"{name} ({kind_name})")
            params = {"experiment": name, "kind": kind_name, "title": title, "well": well,
                      **values.damping_param(blk["damping"]), **kind.resolve(blk, ctx)}
            exp = Experiment(name=name, kind=kind, key=key, params=params, figure=_figure(name, kind, params, decl),
                             products=tuple(kind.products(name, params)), tasks=tuple(kind.tasks(params)))
            self.experiments[name] = exp
            _check_compiled(exp, well)
            if len([p for p in exp.products if p.tiles]) > 1:
                # (with numerics.tiles = 0 each would integrate the charts again)
                raise ValueError(f"experiment {name!r}: more than one product reads its chart tiles")
            for prod in exp.products:
                if prod.path in self._products:
                    other = self._products[prod.path][0].name
                    raise ValueError(f"experiments {other!r} and {name!r} both write {prod.path}")
                self._products[prod.path] = (exp, prod)

    # ------------------------------------------------------------------ lookups
    def params(self) -> dict[str, Params]:
        return {n: e.params for n, e in self.experiments.items()}

    def product(self, path: str | os.PathLike[str]) -> Product:
        return self._products[str(path)][1]

    def experiment_of(self, path: str | os.PathLike[str]) -> Experiment:
        return self._products[str(path)][0]

    def datasets(self, stage: str | None = None) -> list[str]:
        return [p for p, (_, prod) in self._products.items() if stage is None or prod.stage == stage]

    def param_files(self) -> list[str]:
        return [params_path(n) for n in self.experiments]

    def tile_files(self, experiment: str) -> list[str]:
        """Tile files of every task of a chart experiment (tasks x tiles, task-major); none when
        ``numerics.tiles`` is 0."""
        exp = self.experiments[experiment]
        return [tile_path(experiment, k, t, self.tiles) for k in range(len(exp.tasks)) for t in range(self.tiles)]

    def chart_experiments(self) -> list[str]:
        return [n for n, e in self.experiments.items() if e.tasks]

    def integrates_tasks(self, path: str | os.PathLike[str]) -> bool:
        """The dataset ``path`` integrates its experiment's chart tasks in its own job: it reads
        the charts and ``numerics.tiles`` is 0 (no chart_tile jobs)."""
        return self.tiles == 0 and self.product(path).tiles

    def integrates(self, path: str | os.PathLike[str]) -> bool:
        """The dataset's job integrates trajectories or the slow flow (runs with numerics.threads):
        a heavy product, or one integrating its chart tasks."""
        return self.product(path).heavy or self.integrates_tasks(path)

    def product_inputs(self, path: str | os.PathLike[str]) -> dict[str, object]:
        """Snakemake inputs of a dataset: its experiment's parameter file, its tiles (chart kinds
        whose product gathers them) and the files the product names."""
        exp, prod = self._products[str(path)]
        inputs: dict[str, object] = {"params": exp.params_file, **prod.inputs}
        if prod.tiles and self.tiles:
            inputs["tiles"] = self.tile_files(exp.name)
        return inputs

    def figures(self) -> list[FigureSpec]:
        return [e.figure for e in self.experiments.values() if e.figure is not None]

    def experiments_for(self, files: Iterable[str | os.PathLike[str]]) -> set[str] | None:
        """The experiments whose datasets building ``files`` (snakemake target files) needs: a
        dataset, its chart tiles or a figure of an experiment, and the datasets of other
        experiments these read.  None (= every experiment) when that is all of them, or when a file
        under results/ is none of these (a parameter file needs no computation; files outside
        results/ are sources)."""
        figures: dict[str, FigureSpec] = {}
        for f in self.figures():
            for p in (f.png, f.pdf, f.executed_notebook, f"results/captions/{f.name}.rst"):
                figures[p] = f
        need: set[str] = set()
        todo: list[str] = []
        for path in map(_relative, files):
            if path in self._products:
                todo.append(path)
            elif path in figures:
                todo += figures[path].dataset_files()
            elif path.startswith(f"{PARTS_DIR}/") and path.split("/")[4] in self.experiments:
                need.add(path.split("/")[4])
            elif path.startswith(f"{PARAMS_DIR}/") or path.startswith("results/notebooks/templates/"):
                continue
            elif path.startswith("results/"):
                return None
        seen: set[str] = set()
        while todo:
            path = todo.pop()
            if path in seen or path not in self._products:
                continue
            seen.add(path)
            need.add(self.experiment_of(path).name)
            todo += [x for v in self.product_inputs(path).values() for x in (v if isinstance(v, (list, tuple)) else [v])
                     if isinstance(x, str)]
        return None if {n for n, e in self.experiments.items() if e.products} <= need else need


def _relative(path: str | os.PathLike[str]) -> str:
    """A target path as the plan names it (relative to the working directory, normalised)."""
    p = Path(path)
    return Path(os.path.relpath(p) if p.is_absolute() else os.path.normpath(p)).as_posix()


def load_config(paths: Iterable[str | os.PathLike[str]]) -> dict[str, Any]:
    """Merge config files like ``snakemake --configfile`` (later files win, dicts merged); each
    must hold a mapping (or nothing)."""
    cfg: dict[str, Any] = {}
    for path in paths:
        data = load_yaml(path)
        if data is not None and not isinstance(data, dict):
            raise ConfigError(f"config file {path}: must hold a mapping of keys (figures:, experiments:, ...), "
                              f"got a {type(data).__name__}")
        merge_config(cfg, data or {})
    return cfg


def plan(config: dict[str, Any] | str | Path | Sequence[str | Path]) -> Plan:
    """Validate (filling defaults, in place) and resolve a config dict or config file path(s)."""
    if isinstance(config, (str, Path)):
        config = load_config([config])
    elif isinstance(config, (list, tuple)):
        config = load_config(config)
    return Plan(validate_config(config))
