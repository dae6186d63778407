"""Configuration: loading, the schema assembled from the registry, validation naming the key.

The schema is ``schemas/config.schema.yaml`` beside this module (package data: the pipeline, the
command line and an installed wheel read the same file; global knobs and shared building blocks
under ``$defs``) plus one ``$defs`` entry per registered kind (its ``schema``): the paper's
figures (block ``figures``) and the beyond-the-paper products (block ``extras``) refer to
their kind's definition, and blocks under ``experiments`` name theirs with ``kind:``.  Every
config default lives in that schema and is filled in by :func:`validate_config`, which then
runs each kind's ``check``; every failure is a :class:`ConfigError` starting with the dotted
key, e.g. ``config key figures.fig13.xi_max[2]: ...``.

Nothing here imports the theory or numerics code, so a bad configuration is rejected (and the
DAG built) without compiling anything.
"""
from __future__ import annotations

import copy
import importlib
import math
import os
from collections.abc import Iterable, Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import yaml

from safebasins.core.checks import reaches
from safebasins.pipeline import catalog, well_defaults
from safebasins.pipeline.registry import KINDS
from safebasins.pipeline.validation import CheckContext, ConfigError, fail, indexed, key_path

if TYPE_CHECKING:
    from safebasins.pipeline.catalog import Declaration
    from safebasins.pipeline.registry import Block, Kind
    from safebasins.wells.base import Well

#: the package's config schema (shipped inside the package: an installed wheel reads it too)
SCHEMA_PATH = Path(__file__).resolve().parent / "schemas" / "config.schema.yaml"
#: the source checkout holding this package (config/config.yaml, the Snakefile): scripts and tests
#: of a checkout use it; the library reads nothing there
REPO_ROOT = Path(__file__).resolve().parents[3]
#: the kind modules of the package (importing them registers the kinds)
KIND_MODULES = ("safebasins.pipeline.kinds.fcr", "safebasins.pipeline.kinds.basins",
                "safebasins.pipeline.kinds.charts", "safebasins.pipeline.kinds.extras",
                "safebasins.pipeline.kinds.maps", "safebasins.pipeline.kinds.damped",
                "safebasins.pipeline.kinds.basin_measures",
                "safebasins.pipeline.kinds.saddle", "safebasins.pipeline.kinds.fatal_shock",
                "safebasins.pipeline.kinds.continuation", "safebasins.pipeline.kinds.noise")

__all__ = ["ConfigError", "load_yaml", "merge_config", "build_schema", "validate_config", "experiment_blocks",
           "SCHEMA_PATH"]


def load_yaml(path: str | os.PathLike[str]) -> Any:
    """A YAML file as Python data; ConfigError naming the file and the line for a syntax error or
    a key given twice in one mapping (YAML would keep the later value silently)."""
    try:
        with open(path, encoding="utf-8") as fh:
            loader = yaml.SafeLoader(fh)
            try:
                node = loader.get_single_node()
                if node is None:
                    return None
                _check_unique_keys(path, node)
                return loader.construct_document(node)
            finally:
                loader.dispose()
    except OSError as exc:
        raise ConfigError(f"config file {path}: cannot be read ({exc.strerror or exc})") from None
    except UnicodeDecodeError as exc:
        raise ConfigError(f"config file {path}: not UTF-8 text (byte {exc.start}: {exc.reason})") from None
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        where = f", line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        ctx = exc.context and (f"{exc.context} (line {exc.context_mark.line + 1})" if exc.context_mark else exc.context)
        what = "; ".join(str(x) for x in (ctx, exc.problem) if x)
        raise ConfigError(f"config file {path}{where}: not valid YAML ({what})") from None
    except yaml.YAMLError as exc:
        raise ConfigError(f"config file {path}: not valid YAML ({exc})") from None


def _check_unique_keys(path: str | os.PathLike[str], node: yaml.Node, keys: tuple[str | int, ...] = ()) -> None:
    """ConfigError for the first key that a mapping of the YAML node tree repeats."""
    if isinstance(node, yaml.MappingNode):
        seen: dict[str, int] = {}
        for k, v in node.value:
            if isinstance(k, yaml.ScalarNode):
                if k.value in seen:
                    raise ConfigError(f"config file {path}, line {k.start_mark.line + 1}: key "
                                      f"{key_path((*keys, k.value))} is given twice (first on line {seen[k.value]}); "
                                      "YAML would keep the later value silently: remove one")
                seen[k.value] = k.start_mark.line + 1
            _check_unique_keys(path, v, (*keys, k.value if isinstance(k, yaml.ScalarNode) else "?"))
    elif isinstance(node, yaml.SequenceNode):
        for i, v in enumerate(node.value):
            _check_unique_keys(path, v, (*keys, i))


def merge_config(base: dict[str, Any], override: dict[str, Any] | None) -> dict[str, Any]:
    """Merge ``override`` into ``base`` in place like ``snakemake --configfile``: mappings are
    merged key by key, everything else (lists included) is replaced."""
    for k, v in (override or {}).items():
        if isinstance(v, dict) and isinstance(base.get(k), dict):
            merge_config(base[k], v)
        else:
            base[k] = copy.deepcopy(v)
    return base


def load_kinds(extensions: Iterable[str] = ()) -> None:
    """Import the package's kind modules and the config's ``extensions`` (modules registering
    further kinds)."""
    for mod in (*KIND_MODULES, *extensions):
        importlib.import_module(mod)


def well_schema() -> dict[str, Any]:
    """``$defs/well``: the forms of safebasins.wells (the named wells are read from its table)."""
    from safebasins.wells import NAMED_WELLS
    from safebasins.wells.interpolation import DEFAULT_TOL, TOL_RANGE

    # the tol key of a polynomial or expression well (safebasins.wells.numeric.NumericWell's tol)
    tol = {"type": "number", "minimum": TOL_RANGE[0], "maximum": TOL_RANGE[1]}

    names = "; ".join(f"{k}: {d}" for k, (_, d) in NAMED_WELLS.items())
    return {
        "description": ("the potential well V(q) of q'' + V'(q) = F sin(Omega t + Psi) (safebasins.wells): a name "
                        f"({names}), {{polynomial: [c0, c1, c2, ...]}} for V = sum c_k q^k (c0 = c1 = 0, c2 > 0), or "
                        "{expression: '<formula in q>'} (sympy; e.g. '1 - cos(q)'); V(0) = V'(0) = 0, V''(0) > 0, "
                        "escape over a barrier or to an asymptote on at least one side. A polynomial or expression "
                        "may add tol: the relative accuracy of its action-angle interpolants (default "
                        f"{DEFAULT_TOL:g}), "
                        "for a formula whose own rounding does not reach it"),
        "oneOf": [{"enum": list(NAMED_WELLS)},
                  {"type": "object", "additionalProperties": False, "required": ["polynomial"],
                   "properties": {"polynomial": {"type": "array", "minItems": 3, "items": {"type": "number"}},
                                  "tol": tol}},
                  {"type": "object", "additionalProperties": False, "required": ["expression"],
                   "properties": {"expression": {"type": "string", "minLength": 1}, "tol": tol}}],
    }


def build_schema(base: dict[str, Any] | None = None) -> dict[str, Any]:
    """The full JSON schema: the base file plus one ``$defs`` entry per registered kind."""
    schema = copy.deepcopy(load_yaml(SCHEMA_PATH) if base is None else base)
    defs = schema.setdefault("$defs", {})
    defs["well"] = well_schema()
    for name, kind in KINDS.items():
        defs[name] = copy.deepcopy(kind.schema)
        # every experiment may name its well; the quartic keeps the paper's results
        defs[name].setdefault("properties", {})["well"] = {"$ref": "#/$defs/well", "default": "quartic"}
        # and its damping: a kind may declare its own form (a list of curves' values)
        defs[name]["properties"].setdefault("damping", {"$ref": "#/$defs/damping", "default": 0.0})
    props = schema["properties"]
    for d in catalog.DECLARATIONS:
        block, key = d.key
        ref: dict[str, Any] = {"$ref": f"#/$defs/{d.kind}"}
        if block == "extras":
            ref["default"] = {}
        props[block].setdefault("properties", {})[key] = ref
        if block != "extras":  # the figures and the escape-equation study are spelled out in config.yaml
            props[block].setdefault("required", []).append(key)
    props["experiments"]["additionalProperties"] = {
        "type": "object", "required": ["kind"],
        "properties": {"kind": {"enum": sorted(KINDS)}},
    }
    return schema


# --------------------------------------------------------------------------------------
# JSON-schema errors in plain words
# --------------------------------------------------------------------------------------
def _default_filling_validator(schema: dict[str, Any]) -> Any:
    from jsonschema import Draft202012Validator, validators

    base = Draft202012Validator
    validate_properties = base.VALIDATORS["properties"]

    def set_defaults(validator: Any, properties: dict[str, Any], instance: Any, schema_: Any) -> Iterator[Any]:
        if isinstance(instance, dict):
            for prop, sub in properties.items():
                if isinstance(sub, dict) and "default" in sub:
                    instance.setdefault(prop, copy.deepcopy(sub["default"]))
        yield from validate_properties(validator, properties, instance, schema_)

    return validators.extend(base, {"properties": set_defaults})(schema)


def _flatten(errors: Iterable[Any]) -> Iterator[Any]:
    for e in errors:
        if e.context:
            yield from _flatten(e.context)
        else:
            yield e


def _format_schema_error(err: Any, prefix: Sequence[str | int] = ()) -> str:
    path = list(prefix) + list(err.absolute_path)
    key = key_path(path)
    msg = err.message
    if err.validator == "additionalProperties":
        # name the unknown key itself
        extra = [k for k in err.instance if k not in err.schema.get("properties", {})]
        if extra:
            key = key_path(path + [extra[0]])
            if path == ["figures"]:
                names = [d.key[1] for d in catalog.DECLARATIONS if d.key[0] == "figures"]
                msg = f"unknown figure name {extra[0]!r} (expected one of {names[0]} ... {names[-1]})"
            else:
                msg = f"unknown key {extra[0]!r}"
    elif err.validator == "required":
        missing = [k for k in err.validator_value if k not in err.instance]
        if missing:
            key = key_path(path + [missing[0]])
            msg = f"missing required key {missing[0]!r}"
    elif err.validator in ("oneOf", "anyOf") and err.context:
        # report the most specific failure inside the alternatives: the deepest one, and
        # rather a value error (maximum, minimum, ...) than "wrong type" of another branch
        subs = list(_flatten(err.context))
        subs.sort(key=lambda e: (-len(list(e.absolute_path)), e.validator in ("type", "oneOf", "anyOf", "required")))
        sub = subs[0]
        if list(sub.absolute_path) != list(err.absolute_path) or sub.validator not in ("type",):
            return _format_schema_error(sub, prefix)
        what = err.schema.get("description", "see the config schema, safebasins/pipeline/schemas/config.schema.yaml")
        msg = f"{err.instance!r} is not valid here: {what}"
    if err.validator == "pattern" and err.validator_value == "^-?pi$":
        msg = f"{err.instance!r} is not an angle: give a number (radians) or 'pi'"
    return f"config key {key}: {msg}"


def _schema_check(validator: Any, instance: Any, prefix: Sequence[str | int] = ()) -> None:
    errors = list(validator.iter_errors(instance))
    if errors:
        # report the error closest to the offending value (deepest path first)
        errors.sort(key=lambda e: (-len(list(e.absolute_path)), str(e.message)))
        raise ConfigError(_format_schema_error(errors[0], prefix))


# --------------------------------------------------------------------------------------
# validation
# --------------------------------------------------------------------------------------
def experiment_blocks(config: dict[str, Any]) -> list[tuple[str, str, str, Block, Declaration | None]]:
    """``(name, kind name, dotted key, block, declaration or None)`` of every experiment of a
    validated config: the catalog's, then the config's ``experiments``."""
    out: list[tuple[str, str, str, Block, Declaration | None]] = []
    for d in catalog.DECLARATIONS:
        block, key = d.key
        out.append((d.name, d.kind, f"{block}.{key}", config[block][key], d))
    for name, blk in (config.get("experiments") or {}).items():
        out.append((name, blk["kind"], f"experiments.{name}", blk, None))
    return out


def _check_finite(value: Any, path: tuple[str | int, ...] = ()) -> None:
    """Every number in the config is finite (YAML's .nan / .inf pass JSON Schema's type checks)."""
    if isinstance(value, dict):
        for k, v in value.items():
            _check_finite(v, (*path, k))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            _check_finite(v, (*path, i))
    elif isinstance(value, float) and not math.isfinite(value):
        fail(key_path(path), f"must be a finite number, got {value}")


def validate_config(config: object) -> dict[str, Any]:
    """Validate ``config`` in place (filling schema defaults); raise ConfigError naming the key."""
    if not isinstance(config, dict):
        raise ConfigError(f"config key <config>: the configuration must be a mapping, got {type(config).__name__}")
    _check_finite(config)
    ext = config.get("extensions", [])
    if not isinstance(ext, list) or not all(isinstance(m, str) for m in ext):
        fail("extensions", "must be a list of importable module names that register experiment kinds")
    for i, mod in enumerate(ext):
        try:
            importlib.import_module(mod)
        except ImportError as exc:
            fail(f"extensions[{i}]", f"cannot import {mod!r}: {exc}")
    load_kinds()
    schema = build_schema()
    _schema_check(_default_filling_validator(schema), config)
    # experiments declared in the config: their kind's schema (plus `kind` and `title`)
    for name, blk in (config.get("experiments") or {}).items():
        if name in catalog.BY_NAME:
            fail(f"experiments.{name}", f"{name!r} is already an experiment of the package; choose another name")
        sub = copy.deepcopy(schema["$defs"][blk["kind"]])
        sub["properties"] = {"kind": {"enum": [blk["kind"]]}, "title": {"type": "string"}, **sub.get("properties", {})}
        sub["$defs"] = schema["$defs"]
        _schema_check(_default_filling_validator(sub), blk, ("experiments", name))
    exps = experiment_blocks(config)
    ctx = CheckContext(config, kinds={n: k for n, k, *_ in exps}, blocks={n: b for n, _, _, b, _ in exps},
                       keys={n: key for n, _, key, _, _ in exps})
    for name, kind, key, blk, _ in exps:
        well_defaults.fill(blk, KINDS[kind].well_defaults, ctx.well(name))
        _check_well(blk, key, ctx.well(name), KINDS[kind])
        KINDS[kind].check(blk, key, ctx)
    return config


def _check_well(block: Block, key: str, well: Well, kind: Kind) -> None:
    """What depends on the experiment's well: the kind accepts it; every ``xi_max`` (truncation
    level) at most, every ``xi_ini`` below, its barrier energy (the schema only knows they are
    positive); the paper's first harmonic and symmetric displacement bounds only for the quartic."""
    beta = block.get("damping", 0.0)
    if not kind.damped and any(b > 0 for b in (beta if isinstance(beta, list) else [beta])):
        fail(f"{key}.damping", f"kind {kind.name!r} is written for the undamped equation (its theory or figure has "
                               "no damping): remove damping or set it to 0")
    if well.name != "quartic" and not kind.any_well:
        fail(f"{key}.well", f"kind {kind.name!r} is written for the paper's quartic only, not the {well.name} well")
    if well.name != "quartic" and block.get("q_max") not in (None, []):
        fail(f"{key}.q_max", f"q_max is a symmetric displacement bound |q| < q_max (eq 4); the {well.name} well "
                             "escapes through its own barriers: use the energy criterion (xi_max)")
    if well.name != "quartic" and "paper" in (block["fourier"] if isinstance(block.get("fourier"), list)
                                               else [block.get("fourier")]):
        fail(f"{key}.fourier", f"'paper' is the quartic's truncated first harmonic (eq 20); the {well.name} well "
                               "uses its exact first harmonic: set fourier to exact (or [exact])")
    top = well.barrier_energy
    # strict: an energy level of the action-angle map (an orbit exists below the escape energy
    # only); xi_max may equal a barrier's energy, not an asymptote's (the orbit there is unbounded)
    levels = (("xi_max", well.open_at_infinity), ("xi_ini", True), ("xi_top", True))
    for sub, blk in [("", block)] + [(f".{k}", v) for k, v in block.items() if isinstance(v, dict)]:
        for name, strict in levels:
            vals = blk.get(name)
            for i, x in enumerate(vals if isinstance(vals, list) else [] if vals is None else [vals]):
                if not isinstance(x, (int, float)):
                    continue
                if x > top or (strict and reaches(x, top)):
                    what = "below" if strict else "at most"
                    fail(indexed(f"{key}{sub}.{name}", vals, i),
                         f"{x} must be {what} the barrier energy {top:.6g} of the {well.name} well"
                         + (" (within a relative 1e-12 of it, which counts as at it)" if x < top else ""))
