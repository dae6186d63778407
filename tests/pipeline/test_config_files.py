"""The configuration's files: the schema ships inside the package (one copy), every config file
must hold a mapping of UTF-8 text, and `make reproduce` points a user whose --configfile
Snakemake cannot parse (it names no file or line) to `safebasins check-config`."""
from __future__ import annotations

import fnmatch
import shutil
import subprocess
import tomllib
from pathlib import Path

import pytest

import safebasins
from safebasins.pipeline.config import REPO_ROOT, SCHEMA_PATH, ConfigError, load_yaml
from safebasins.pipeline.plan import load_config, plan

BASE = REPO_ROOT / "config" / "config.yaml"


def test_the_schema_is_package_data_and_has_one_copy():
    package = Path(safebasins.__file__).resolve().parent
    assert SCHEMA_PATH.is_file() and SCHEMA_PATH.is_relative_to(package)
    rel = SCHEMA_PATH.relative_to(package / "pipeline").as_posix()
    data = tomllib.loads((REPO_ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]
    assert any(fnmatch.fnmatch(rel, g) for g in data["safebasins.pipeline"]), (rel, data)
    assert load_yaml(SCHEMA_PATH)["title"] == "safebasins pipeline configuration"
    if (REPO_ROOT / ".git").exists():
        tracked = subprocess.run(["git", "-C", str(REPO_ROOT), "ls-files"], capture_output=True, text=True,
                                 check=True).stdout.split()
        schemas = [f for f in tracked if f.endswith("config.schema.yaml")]
        assert schemas == ["src/safebasins/pipeline/schemas/config.schema.yaml"], schemas


def test_a_config_file_must_hold_a_mapping(tmp_path):
    f = tmp_path / "list.yaml"
    f.write_text("- figures\n- numerics\n")
    with pytest.raises(ConfigError, match=rf"^config file {f}: must hold a mapping of keys .* got a list$"):
        plan([BASE, f])
    f.write_text("just text\n")
    with pytest.raises(ConfigError, match=rf"^config file {f}: must hold a mapping of keys .* got a str$"):
        load_config([f])
    # an empty file adds nothing; merging keeps the later value, dicts key by key
    e, o = tmp_path / "empty.yaml", tmp_path / "o.yaml"
    e.write_text("# nothing yet\n")
    o.write_text("numerics: {tiles: 3}\n")
    cfg = load_config([BASE, e, o])
    assert cfg["numerics"]["tiles"] == 3
    assert cfg["numerics"]["steps_per_cycle"] == load_yaml(BASE)["numerics"]["steps_per_cycle"]


def test_a_config_file_must_be_utf8(tmp_path):
    f = tmp_path / "latin1.yaml"
    f.write_bytes("title: caf\u00e9\n".encode("latin-1"))
    with pytest.raises(ConfigError, match=rf"^config file {f}: not UTF-8 text \(byte 10: invalid continuation byte\)$"):
        load_yaml(f)


@pytest.mark.skipif(shutil.which("make") is None or not (REPO_ROOT / ".venv" / "bin" / "snakemake").exists(),
                    reason="needs make and the checkout's .venv (make test creates both)")
def test_make_reproduce_names_check_config_when_snakemake_cannot_parse_a_configfile(tmp_path):
    f = tmp_path / "bad.yaml"
    f.write_text("figures:\n  fig13: {cycles: [1, 2}\n")
    # -o: never reinstall the environment here; snakemake stops while reading its arguments
    cmd = ["make", "-s", "-o", ".venv/.installed", "reproduce", "REPORT=", f"SNAKEMAKE_ARGS=--configfile {f}"]
    res = subprocess.run(cmd, cwd=REPO_ROOT, capture_output=True, text=True, timeout=300)
    out = res.stdout + res.stderr
    assert res.returncode != 0
    assert "Config file is not valid JSON or YAML" in out, out
    assert ".venv/bin/safebasins check-config FILE names both" in out, out
    # and the command it names does
    res = subprocess.run([str(REPO_ROOT / ".venv" / "bin" / "safebasins"), "check-config", str(f)], cwd=REPO_ROOT,
                         capture_output=True, text=True, timeout=120)
    assert res.returncode == 1 and f"config file {f}, line 2, column 24: not valid YAML" in res.stderr, res.stderr
