"""The ``check-config`` command: a pipeline configuration checked as ``snakemake`` would, nothing run.

The files are read by the pipeline's strict loader (a YAML syntax error or a key given twice
names the file, line and column), merged like ``snakemake --configfile`` over the base
configuration, then validated and planned (:func:`safebasins.pipeline.plan.plan`: the schema,
the kinds' checks, the wells, the compiled forms) and priced by the pipeline's cost guard.  An
error names the key and, where one of the files sets it, that file and line.
"""
from __future__ import annotations

import os
import re
from collections.abc import Iterable, Sequence
from pathlib import Path

import click
import yaml

__all__ = ["check_config", "key_location"]

#: the pipeline's configuration in a checkout, relative to where snakemake runs
BASE = Path("config") / "config.yaml"


def _key_parts(key: str) -> list[str | int]:
    """``figures.fig13.xi_max[2]`` -> ``["figures", "fig13", "xi_max", 2]``."""
    parts: list[str | int] = []
    for name, index in re.findall(r"([^.\[\]]+)|\[(\d+)\]", key):
        parts.append(int(index) if index else name)
    return parts


def _depth_and_line(node: yaml.Node, parts: Sequence[str | int]) -> tuple[int, int]:
    """How many leading ``parts`` the YAML node tree holds, and the line of the deepest one."""
    depth, line = 0, node.start_mark.line + 1
    for part in parts:
        child = None
        if isinstance(node, yaml.MappingNode) and isinstance(part, str):
            child = next(((k, v) for k, v in node.value if isinstance(k, yaml.ScalarNode) and k.value == part), None)
        elif isinstance(node, yaml.SequenceNode) and isinstance(part, int) and part < len(node.value):
            child = (node.value[part], node.value[part])
        if child is None:
            break
        depth, line, node = depth + 1, child[0].start_mark.line + 1, child[1]
    return depth, line


def key_location(key: str, files: Iterable[str | os.PathLike[str]]) -> tuple[str, int, bool] | None:
    """(file, line, whole key) where the last of ``files`` that sets the dotted config ``key``
    sets it, or else holds the deepest block on its way (whole key False); None when no file
    holds even its first part."""
    parts, best = _key_parts(key), None
    for f in files:
        try:
            node = yaml.compose(Path(f).read_text(encoding="utf-8"), Loader=yaml.SafeLoader)
        except (OSError, yaml.YAMLError):
            continue
        if node is None:
            continue
        depth, line = _depth_and_line(node, parts)
        if depth and (best is None or depth >= best[0]):
            best = (depth, str(f), line)
    return None if best is None else (best[1], best[2], best[0] == len(parts))


@click.command("check-config")
@click.argument("files", nargs=-1, required=True, metavar="FILE...",
                type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--base", "base", type=click.Path(exists=True, dir_okay=False, path_type=Path), default=None,
              help=f"Configuration the files are merged over, as snakemake merges --configfile over the "
                   f"Snakefile's  [default: {BASE} when the current directory has one (a checkout)]")
@click.option("--no-base", "no_base", is_flag=True,
              help="Check the files merged on their own (a complete configuration).")
def check_config(files: tuple[Path, ...], base: Path | None, no_base: bool) -> None:
    """Check pipeline configuration files without running anything.

    Reads each file strictly (YAML syntax errors and keys given twice with file, line and
    column), merges them over the checkout's config/config.yaml as `snakemake --configfile
    FILE...` does, and applies every check the pipeline applies before its first job: the schema,
    the experiment kinds' checks, the wells, the cost guard.  Exit status 0 when the pipeline
    would accept the configuration, 1 (with the reason) when not.

    \b
    Examples:
      safebasins check-config my_experiment.yaml
      safebasins check-config --no-base my_complete_config.yaml
    """
    from safebasins.pipeline.cost import guard
    from safebasins.pipeline.plan import plan
    from safebasins.pipeline.validation import ConfigError

    if base is not None and no_base:
        raise click.UsageError("give either --base or --no-base")
    implicit = base is None and not no_base
    if implicit and BASE.is_file():
        base = BASE
    paths = ([base] if base is not None else []) + list(files)
    try:
        run = plan([str(p) for p in paths])
        summary = guard(run)
    except (ConfigError, ValueError) as exc:
        msg = str(exc)
        m = re.match(r"config key (\S+): ", msg)
        where = key_location(m.group(1), paths) if m else None
        if where is not None:
            msg += f"\n  ({'set' if where[2] else 'in the block'} at {where[0]}, line {where[1]})"
        if implicit and base is None:
            msg += (f"\n  (checked without a base configuration: no {BASE} in this directory; run the "
                    "command in the checkout, or give --base path/to/config/config.yaml)")
        raise click.ClickException(msg) from None
    over = f" merged over {base}" if base is not None else ""
    click.echo(f"{', '.join(map(str, files))}{over}: valid ({len(run.experiments)} experiments, "
               f"{len(run.datasets())} datasets, {len(run.figures())} figures)")
    click.echo(summary)
