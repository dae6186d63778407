"""Pipeline configuration: validation, resolution into per-experiment parameters, helpers.

The Snakemake workflow (``Snakefile``, ``workflow/rules/*.smk``) and the rule scripts
(``scripts/*.py``) use this module; nothing here imports the theory or numerics code, so
the DAG can be built (and a bad configuration rejected) without compiling anything.

* :func:`validate_config` checks a configuration dict against
  ``workflow/schemas/config.schema.yaml`` (filling the schema defaults in place) plus the
  checks JSON Schema cannot express; every failure is a :class:`ConfigError` whose message
  starts with the dotted key, e.g. ``figures.fig13.xi_max[2]``.
* :func:`resolve` turns a validated configuration into one plain dict per experiment (the
  content of ``results/params/{experiment}.yaml``): every grid, Omega list, threshold, seed
  and task written out, so each downstream file depends on its own parameters only.
* :func:`dataset_files` names the datasets each experiment produces (docs/contracts.md).
"""
from __future__ import annotations

import copy
import hashlib
import json
import math
import os
import sys
from pathlib import Path

import numpy as np
import yaml

REPO_ROOT = Path(__file__).resolve().parents[2]
SCHEMA_PATH = REPO_ROOT / "workflow" / "schemas" / "config.schema.yaml"

EXPERIMENTS = tuple(f"fig{i:02d}" for i in range(1, 23))

#: experiment -> kind of computation (decides which rules serve it)
KINDS = {
    **{f"fig{i:02d}": "fcr_theory" for i in (1, 2, 3, 4)},
    **{f"fig{i:02d}": "basin_rm" for i in (5, 6, 7, 8, 9)},
    **{f"fig{i:02d}": "fcr_compare" for i in (10, 11, 12)},
    **{f"fig{i:02d}": "basin_chart" for i in (13, 14, 15, 16, 17)},
    "fig18": "strobe",
    "fig19": "criteria",
    "fig20": "chart",
    "fig21": "chart",
    "fig22": "area_time",
}

TITLES = {
    "fig01": "Critical forcing F_cr(Omega) for several initial energies xi_ini (gamma_ini = 0.25, xi_max = 0.242)",
    "fig02": "Critical forcing F_cr(Omega) for several initial angles gamma_ini (xi_ini = 0.15, xi_max = 0.242)",
    "fig03": "Critical forcing F_cr(Omega) for the zero IC, xi_max = 0.15: SMM, SM and MM branches",
    "fig04": "Critical forcing F_cr(Omega) for the zero IC and several truncation levels xi_max",
    "fig05": "Safe basin of maximum type, island kind (F = 0.0876, Omega = 0.92, xi_max = 0.24)",
    "fig06": "Safe basin of maximum type, peninsula kind (F = 0.0876, Omega = 1.04, xi_max = 0.249)",
    "fig07": "Safe basin of maximum type, peninsula kind (F = 0.0876, Omega = 0.57, xi_max = 0.21)",
    "fig08": "Safe basin of saddle type (F = 0.0876, Omega = 0.57, xi_max = 0.2499)",
    "fig09": "Coexisting safe basins of both types (F = 0.0478, Omega = 0.76, xi_max = 0.235)",
    "fig10": "Analytic versus numeric F_cr(Omega), zero IC, three truncation levels",
    "fig11": "Analytic versus numeric F_cr(Omega), several xi_ini (gamma_ini = 0.25, Psi = pi, xi_max = 0.242)",
    "fig12": "Analytic versus numeric F_cr(Omega), several gamma_ini (xi_ini = 0.15, Psi = pi, xi_max = 0.242)",
    "fig13": "Safe basins versus xi_max, analytic and numeric (F = 0.015, Omega = 1.04, Psi = pi)",
    "fig14": "Safe basins versus xi_max, analytic and numeric (F = 0.01, Omega = 0.9, Psi = pi)",
    "fig15": "Safe basins versus xi_max, analytic and numeric (F = 0.01, Omega = 0.9, Psi = 1)",
    "fig16": "Safe basins versus F, analytic and numeric (xi_max = 0.18, Omega = 0.9, Psi = pi)",
    "fig17": "Safe basins versus F, analytic and numeric (xi_max = 0.22, Omega = 0.9, Psi = pi)",
    "fig18": "Stroboscopic map of non-escaping trajectories (F = 0.0876, Omega = 0.99, Psi = pi, xi_max = 0.24)",
    "fig19": "Energy versus displacement escape criterion: safe-basin areas of random ICs",
    "fig20": "Escape chart, zoomed window (F = 0.0876, Omega = 0.95, Psi = pi, xi_max = 0.25)",
    "fig21": "Escape chart, entire window (F = 0.0876, Omega = 0.95, Psi = pi, xi_max = 0.25)",
    "fig22": "Safe-basin area versus evaluation time (read from the Fig 21 chart)",
}

#: beyond-the-paper experiments (config block `extras:`), resolved like the figures into
#: results/params/extra_<name>.yaml; config key -> experiment name
EXTRA_KEYS = {"erosion": "extra_erosion", "true_basin": "extra_true_basin", "fourier_compare": "extra_fourier"}
EXTRAS = tuple(EXTRA_KEYS.values())
KINDS.update({"extra_erosion": "erosion", "extra_true_basin": "true_basin", "extra_fourier": "fourier_compare"})
TITLES.update({
    "extra_erosion": "Erosion profiles: GIM, LIM and IF versus F, analytic (paper and exact G) and numeric",
    "extra_true_basin": "Phase-invariant (true) safe basin: intersection over the forcing phase Psi",
    "extra_fourier": "First harmonic of the slow flow: paper's G (eq 20) versus the exact one, against the numerics",
})

# seeds: config `seed` plus a fixed per-experiment offset, so experiments never share streams
SEED_OFFSET = {"fig18": 18_000, "fig19": 19_000}


class ConfigError(ValueError):
    """A configuration error; the message starts with the offending key."""


# --------------------------------------------------------------------------------------
# validation
# --------------------------------------------------------------------------------------
def _key(path) -> str:
    out = ""
    for part in path:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out or "<config>"


def load_yaml(path):
    with open(path) as fh:
        return yaml.safe_load(fh)


def _default_filling_validator(schema):
    import jsonschema
    from jsonschema import Draft202012Validator, validators

    base = Draft202012Validator
    validate_properties = base.VALIDATORS["properties"]

    def set_defaults(validator, properties, instance, schema_):
        if isinstance(instance, dict):
            for prop, sub in properties.items():
                if isinstance(sub, dict) and "default" in sub:
                    instance.setdefault(prop, copy.deepcopy(sub["default"]))
        yield from validate_properties(validator, properties, instance, schema_)

    cls = validators.extend(base, {"properties": set_defaults})
    del jsonschema
    return cls(schema)


def _best_error(errors):
    from jsonschema.exceptions import best_match

    return best_match(errors)


def _flatten(errors):
    for e in errors:
        if e.context:
            yield from _flatten(e.context)
        else:
            yield e


def _format_schema_error(err) -> str:
    path = list(err.absolute_path)
    key = _key(path)
    msg = err.message
    if err.validator == "additionalProperties":
        # name the unknown key itself
        extra = [k for k in err.instance if k not in err.schema.get("properties", {})]
        if extra:
            key = _key(path + [extra[0]])
            if path == ["figures"]:
                msg = f"unknown figure name {extra[0]!r} (expected one of fig01 ... fig22)"
            else:
                msg = f"unknown key {extra[0]!r}"
    elif err.validator == "required":
        missing = [k for k in err.validator_value if k not in err.instance]
        if missing:
            key = _key(path + [missing[0]])
            msg = f"missing required key {missing[0]!r}"
    elif err.validator in ("oneOf", "anyOf") and err.context:
        # report the most specific failure inside the alternatives: the deepest one, and
        # rather a value error (maximum, minimum, ...) than "wrong type" of another branch
        subs = list(_flatten(err.context))
        subs.sort(key=lambda e: (-len(list(e.absolute_path)), e.validator in ("type", "oneOf", "anyOf", "required")))
        sub = subs[0]
        if list(sub.absolute_path) != path or sub.validator not in ("type",):
            return _format_schema_error(sub)
        msg = f"{err.instance!r} is not valid here: {err.schema.get('description', 'see workflow/schemas/config.schema.yaml')}"
    if err.validator == "pattern" and err.validator_value == "^-?pi$":
        msg = f"{err.instance!r} is not an angle: give a number (radians) or 'pi'"
    return f"config key {key}: {msg}"


def validate_config(config: dict, schema=None) -> dict:
    """Validate `config` in place (filling schema defaults); raise ConfigError naming the key."""
    if not isinstance(config, dict):
        raise ConfigError(f"config key <config>: the configuration must be a mapping, got {type(config).__name__}")
    if schema is None:
        schema = SCHEMA_PATH
    if not isinstance(schema, dict):
        schema = load_yaml(schema)
    validator = _default_filling_validator(schema)
    errors = list(validator.iter_errors(config))
    if errors:
        # report the error closest to the offending value (deepest path first)
        errors.sort(key=lambda e: (-len(list(e.absolute_path)), str(e.message)))
        raise ConfigError(_format_schema_error(errors[0]))
    _semantic_checks(config)
    return config


def _fail(key, msg):
    raise ConfigError(f"config key {key}: {msg}")


def _as_list(v):
    return list(v) if isinstance(v, (list, tuple)) else [v]


def _check_range(key, r, *, positive=False):
    start, stop = float(r["start"]), float(r["stop"])
    if not (math.isfinite(start) and math.isfinite(stop)):
        _fail(key, "start and stop must be finite")
    if stop < start or (stop == start and r.get("num", 1) != 1):
        _fail(key, f"empty range: stop ({stop}) must be greater than start ({start})")
    if "step" in r and r["step"] > stop - start and stop > start:
        _fail(f"{key}.step", f"step {r['step']} is larger than the range [{start}, {stop}]")
    if positive and start <= 0:
        _fail(f"{key}.start", f"must be > 0, got {start}")


def _check_interval(key, iv):
    lo, hi = iv
    if not hi > lo:
        _fail(key, f"empty interval [{lo}, {hi}]: the second value must be greater than the first")


def _check_grid(key, g):
    _check_interval(f"{key}.q0", g["q0"])
    _check_interval(f"{key}.p0", g["p0"])


def _angle(v):
    if isinstance(v, str):
        return -math.pi if v.strip().startswith("-") else math.pi
    return float(v)


def _check_extras(config):
    ext = config.get("extras") or {}
    tiles = config.get("numerics", {}).get("tiles", 1)
    figs = config["figures"]
    for key in ("erosion", "true_basin"):
        blk = ext.get(key)
        if blk is None:
            continue
        base = f"extras.{key}"
        _check_grid(f"{base}.grid", blk["grid"])
        n = blk["grid"]["n"]
        nq = n if isinstance(n, int) else n[0]
        if tiles > nq:
            _fail("numerics.tiles", f"{tiles} tiles but {base}.grid has only {nq} q0 rows")
        for i, x in enumerate(_as_list(blk["xi_max"])):
            if x >= 0.25:
                _fail(f"{base}.xi_max" + (f"[{i}]" if isinstance(blk["xi_max"], list) else ""),
                      f"the analytic criterion needs xi_max < 0.25 (G(1/4) = 0 is degenerate), got {x}")
        t = _as_list(blk["t_eval"])
        if max(t) > blk["cycles"]:
            _fail(f"{base}.t_eval", f"evaluation time {max(t)} beyond the horizon cycles = {blk['cycles']}")
    blk = ext.get("erosion")
    if blk is not None and isinstance(blk["F"], dict):
        _check_range("extras.erosion.F", blk["F"])
        if blk["F"]["start"] < 0:
            _fail("extras.erosion.F.start", f"must be >= 0 (a forcing amplitude), got {blk['F']['start']}")
    blk = ext.get("fourier_compare")
    if blk is not None:
        for key, kinds in (("fcr", ("fcr_compare",)), ("iou", ("basin_chart",))):
            seen = set()
            for i, name in enumerate(blk[key]):
                if KINDS.get(name) not in kinds:
                    _fail(f"extras.fourier_compare.{key}[{i}]",
                          f"{name!r} has no {'numeric F_cr' if key == 'fcr' else 'escape chart with analytic counterpart'}"
                          f" dataset (choose among {', '.join(e for e in EXPERIMENTS if KINDS[e] in kinds)})")
                if name in seen:
                    _fail(f"extras.fourier_compare.{key}[{i}]", f"{name!r} listed twice")
                seen.add(name)
            if key == "iou" and blk.get("t_eval") is not None:
                for name in blk[key]:
                    hor = figs.get(name, {}).get("cycles", 3000)
                    if blk["t_eval"] > hor:
                        _fail("extras.fourier_compare.t_eval",
                              f"{blk['t_eval']} is beyond the horizon of {name} (cycles = {hor})")


def _semantic_checks(config):
    _check_extras(config)
    figs = config["figures"]
    tiles = config.get("numerics", {}).get("tiles", 1)
    for name, blk in figs.items():
        kind = KINDS[name]
        if kind in ("basin_chart", "chart") and "grid" in blk:
            n = blk["grid"]["n"]
            nq = n if isinstance(n, int) else n[0]
            if tiles > nq:
                _fail("numerics.tiles", f"{tiles} tiles but figures.{name}.grid has only {nq} q0 rows")
        if kind == "criteria" and tiles > blk["n_ic"] * blk["repeats"]:
            _fail("numerics.tiles", f"{tiles} tiles but figures.{name} has only n_ic * repeats ICs")
    for name, blk in figs.items():
        kind = KINDS[name]
        base = f"figures.{name}"
        if "Omega" in blk and isinstance(blk["Omega"], dict):
            _check_range(f"{base}.Omega", blk["Omega"], positive=True)
        if "grid" in blk:
            _check_grid(f"{base}.grid", blk["grid"])
        if "box" in blk:
            _check_interval(f"{base}.box[0]", blk["box"][0])
            _check_interval(f"{base}.box[1]", blk["box"][1])
        if kind in ("fcr_theory", "fcr_compare"):
            lens = {k: len(_as_list(blk[k])) for k in ("xi_max", "xi_ini", "gamma_ini")}
            n = max(lens.values())
            for k, m in lens.items():
                if m not in (1, n):
                    _fail(f"{base}.{k}", f"has {m} values but another curve list has {n}: lists must have equal length")
            xm = _as_list(blk["xi_max"]) * (n // lens["xi_max"])
            xi = _as_list(blk["xi_ini"]) * (n // lens["xi_ini"])
            for i, (a, b) in enumerate(zip(xm, xi)):
                if a >= 0.25:
                    _fail(f"{base}.xi_max" + (f"[{i}]" if lens["xi_max"] > 1 else ""),
                          f"analytic F_cr needs xi_max < 0.25 (the action-angle map is singular on the separatrix), got {a}")
                if b >= a:
                    _fail(f"{base}.xi_ini" + (f"[{i}]" if lens["xi_ini"] > 1 else ""),
                          f"initial energy {b} must be below the truncation level xi_max = {a}")
            if kind == "fcr_compare":
                num = blk["numeric"]
                _check_range(f"{base}.numeric.Omega", num["Omega"], positive=True)
                lo, hi = num["F_bracket"]
                if not hi > lo:
                    _fail(f"{base}.numeric.F_bracket", f"empty bracket [{lo}, {hi}]")
        if kind in ("basin_rm", "basin_chart", "strobe"):
            for i, x in enumerate(_as_list(blk["xi_max"])):
                if x >= 0.25:
                    _fail(f"{base}.xi_max" + (f"[{i}]" if isinstance(blk["xi_max"], list) else ""),
                          f"an analytic safe basin needs xi_max < 0.25 (separatrix singular), got {x}")
        if kind == "basin_rm":
            man = blk.get("manifold", {})
            if man.get("xi_top", 0.2499) <= 0:
                _fail(f"{base}.manifold.xi_top", "must be > 0")
        if kind == "basin_chart":
            fl, xl = isinstance(blk["F"], list), isinstance(blk["xi_max"], list)
            if fl and xl:
                _fail(f"{base}.F", "only one of F and xi_max may be a list (the scanned parameter)")
        if kind == "strobe" and blk["n_trajectories"] > blk["n_candidates"]:
            _fail(f"{base}.n_trajectories",
                  f"{blk['n_trajectories']} trajectories requested but only n_candidates = {blk['n_candidates']} drawn")
        if kind == "criteria" and isinstance(blk["F"], dict):
            _check_range(f"{base}.F", blk["F"])
            if blk["F"]["start"] < 0:
                _fail(f"{base}.F.start", f"must be >= 0 (a forcing amplitude), got {blk['F']['start']}")
        if kind == "chart":
            if "t_eval" in blk and max(blk["t_eval"]) > blk["cycles"]:
                _fail(f"{base}.t_eval", f"evaluation time {max(blk['t_eval'])} beyond the horizon cycles = {blk['cycles']}")
            if not _as_list(blk["xi_max"]) and not _as_list(blk["q_max"]):
                _fail(f"{base}.xi_max", "at least one threshold needed")
        if kind == "area_time":
            _check_range(f"{base}.t_eval", blk["t_eval"])
            src = figs.get(blk["source"])
            if src is not None and blk["t_eval"]["stop"] > src.get("cycles", 3000):
                _fail(f"{base}.t_eval.stop",
                      f"{blk['t_eval']['stop']} is beyond the horizon of {blk['source']} (cycles = {src.get('cycles', 3000)})")


# --------------------------------------------------------------------------------------
# resolution
# --------------------------------------------------------------------------------------
def range_values(r) -> list[float]:
    """Values of a {start, stop, num} or {start, stop, step} range (endpoints included)."""
    start, stop = float(r["start"]), float(r["stop"])
    if "num" in r:
        vals = np.linspace(start, stop, int(r["num"]))
    else:
        step = float(r["step"])
        n = int(math.floor((stop - start) / step + 1e-9)) + 1
        vals = start + step * np.arange(n)
    # round away float noise (0.30000000000000004) so YAML files read well and stay stable
    return [float(np.round(v, 12)) for v in vals]


def q_max_from_xi(xi_max: float) -> float:
    """Eq (4); duplicated here so the DAG builds without importing the theory code."""
    return float(math.sqrt(1.0 - math.sqrt(1.0 - 4.0 * xi_max)))


def _grid(g):
    n = g["n"]
    nq, np_ = (n, n) if isinstance(n, int) else (int(n[0]), int(n[1]))
    return {"q0": [float(g["q0"][0]), float(g["q0"][1])], "p0": [float(g["p0"][0]), float(g["p0"][1])],
            "n": [nq, np_]}


def _curves(blk, with_psi):
    lists = {k: _as_list(blk[k]) for k in ("xi_max", "xi_ini", "gamma_ini")}
    n = max(len(v) for v in lists.values())
    varying = [k for k, v in lists.items() if len(v) > 1]
    curves = []
    for i in range(n):
        c = {k: (v[i] if len(v) > 1 else v[0]) for k, v in lists.items()}
        xi_max, xi0, gamma0 = float(c["xi_max"]), float(c["xi_ini"]), _angle(c["gamma_ini"])
        if varying:
            label = ", ".join(f"{k} = {_fmt(c[k])}" for k in varying)
        else:
            label = f"xi_max = {_fmt(xi_max)}"
        cur = {"label": label, "xi_max": xi_max, "xi0": xi0, "gamma0": gamma0}
        if with_psi:
            cur["Psi"] = _angle(blk["Psi"])
        curves.append(cur)
    return curves


def _fmt(v):
    if isinstance(v, str):
        return v
    return f"{float(v):g}"


def resolve(config: dict) -> dict[str, dict]:
    """Validated configuration -> {experiment: fully resolved parameters (plain Python)}."""
    figs = config["figures"]
    num = config["numerics"]
    spc = int(num["steps_per_cycle"])
    fourier = config["fourier"]
    seed = int(config["seed"])
    out = {}
    for name in EXPERIMENTS:
        blk = figs[name]
        kind = KINDS[name]
        p = {"experiment": name, "kind": kind, "title": TITLES[name]}
        if kind == "fcr_theory":
            p.update(fourier=fourier, Omega=range_values(blk["Omega"]), curves=_curves(blk, False))
        elif kind == "fcr_compare":
            nb = blk["numeric"]
            p.update(fourier=fourier, Omega=range_values(blk["Omega"]), curves=_curves(blk, True),
                     numeric={"Omega": range_values(nb["Omega"]), "cycles": int(nb["cycles"]),
                              "tol": float(nb["tol"]), "F_bracket": [float(x) for x in nb["F_bracket"]],
                              "n_scan": int(nb["n_scan"]), "criterion": nb["criterion"],
                              "steps_per_cycle": spc})
        elif kind == "basin_rm":
            man = blk["manifold"]
            p.update(fourier=fourier, F=float(blk["F"]), Omega=float(blk["Omega"]), Psi=_angle(blk["Psi"]),
                     xi_max=float(blk["xi_max"]), grid=_grid(blk["grid"]), n_points=int(blk["n_points"]),
                     manifold={"n_gamma": int(man["n_gamma"]), "n_xi": int(man["n_xi"]),
                               "xi_top": float(man["xi_top"])})
        elif kind == "basin_chart":
            scan = "F" if isinstance(blk["F"], list) else "xi_max"
            Fs = [float(f) for f in _as_list(blk["F"])]
            xis = [float(x) for x in _as_list(blk["xi_max"])]
            p.update(fourier=fourier, scan=scan, F=Fs if scan == "F" else Fs[0],
                     xi_max=xis if scan == "xi_max" else xis[0], Omega=float(blk["Omega"]),
                     Psi=_angle(blk["Psi"]), grid=_grid(blk["grid"]), cycles=int(blk["cycles"]),
                     n_points=int(blk["n_points"]), steps_per_cycle=spc,
                     tasks=[{"F": f, "xi_max": xis, "q_max": []} for f in Fs])
        elif kind == "strobe":
            xi = float(blk["xi_max"])
            box = blk.get("box") or [[-q_max_from_xi(xi), q_max_from_xi(xi)],
                                     [-math.sqrt(2 * xi), math.sqrt(2 * xi)]]
            p.update(fourier=fourier, F=float(blk["F"]), Omega=float(blk["Omega"]), Psi=_angle(blk["Psi"]),
                     xi_max=xi, grid=_grid(blk["grid"]), n_points=int(blk["n_points"]),
                     n_trajectories=int(blk["n_trajectories"]), n_candidates=int(blk["n_candidates"]),
                     n_iter=int(blk["n_iter"]), box=[[float(a), float(b)] for a, b in box],
                     seed=seed + SEED_OFFSET[name], steps_per_cycle=spc)
        elif kind == "criteria":
            Fs = range_values(blk["F"]) if isinstance(blk["F"], dict) else [float(f) for f in blk["F"]]
            xi = float(blk["xi_max"])
            qm = q_max_from_xi(xi) if blk["q_max"] is None else float(blk["q_max"])
            reps = int(blk["repeats"])
            p.update(F=Fs, Omega=float(blk["Omega"]), Psi=_angle(blk["Psi"]), xi_max=xi, q_max=qm,
                     n_ic=int(blk["n_ic"]), repeats=reps, seeds=[seed + SEED_OFFSET[name] + r for r in range(reps)],
                     box=[[float(a), float(b)] for a, b in blk["box"]], cycles=int(blk["cycles"]),
                     steps_per_cycle=spc, tasks=[{"F": f, "xi_max": [xi], "q_max": [qm]} for f in Fs])
        elif kind == "chart":
            xis = [float(x) for x in _as_list(blk["xi_max"])]
            qms = [float(x) for x in _as_list(blk["q_max"])]
            p.update(F=float(blk["F"]), Omega=float(blk["Omega"]), Psi=_angle(blk["Psi"]), xi_max=xis,
                     q_max=qms, grid=_grid(blk["grid"]), cycles=int(blk["cycles"]),
                     t_eval=[float(t) for t in blk.get("t_eval", [blk["cycles"]])], steps_per_cycle=spc,
                     tasks=[{"F": float(blk["F"]), "xi_max": xis, "q_max": qms}])
        elif kind == "area_time":
            p.update(source=blk["source"], t_eval=range_values(blk["t_eval"]))
        out[name] = p
    out.update(resolve_extras(config))
    return out


def resolve_extras(config: dict) -> dict[str, dict]:
    """Validated configuration -> {extra experiment: resolved parameters} (block `extras:`)."""
    ext = config.get("extras") or {}
    spc = int(config["numerics"]["steps_per_cycle"])
    out = {}
    for key, name in EXTRA_KEYS.items():
        blk = ext.get(key)
        if blk is None:
            continue
        p = {"experiment": name, "kind": KINDS[name], "title": TITLES[name]}
        if key == "erosion":
            Fs = range_values(blk["F"]) if isinstance(blk["F"], dict) else [float(f) for f in blk["F"]]
            xis = [float(x) for x in _as_list(blk["xi_max"])]
            p.update(fourier=[str(f) for f in _as_list(blk["fourier"])], F=Fs, Omega=float(blk["Omega"]),
                     Psi=_angle(blk["Psi"]), xi_max=xis, grid=_grid(blk["grid"]), cycles=int(blk["cycles"]),
                     t_eval=[float(t) for t in _as_list(blk["t_eval"])], level=float(blk["level"]),
                     steps_per_cycle=spc,
                     tasks=[{"F": f, "xi_max": xis, "q_max": []} for f in Fs])
        elif key == "true_basin":
            xis = [float(x) for x in _as_list(blk["xi_max"])]
            n = int(blk["n_psi"])
            psis = [float(np.round(2 * math.pi * k / n, 12)) for k in range(n)]
            p.update(fourier=[str(f) for f in _as_list(blk["fourier"])], F=float(blk["F"]),
                     Omega=float(blk["Omega"]), xi_max=xis, Psi=psis, grid=_grid(blk["grid"]),
                     cycles=int(blk["cycles"]), t_eval=[float(t) for t in _as_list(blk["t_eval"])],
                     n_gamma=int(blk["n_gamma"]), steps_per_cycle=spc,
                     tasks=[{"F": float(blk["F"]), "Psi": ps, "xi_max": xis, "q_max": []} for ps in psis])
        else:
            p.update(fcr=list(blk["fcr"]), iou=list(blk["iou"]),
                     t_eval=None if blk.get("t_eval") is None else float(blk["t_eval"]))
        out[name] = p
    return out


def params_hash(params: dict) -> str:
    """SHA-256 of the canonical JSON of one experiment's resolved parameters."""
    return hashlib.sha256(json.dumps(params, sort_keys=True, separators=(",", ":")).encode()).hexdigest()


def config_hash(config: dict) -> str:
    return params_hash(config)


def dump_params(params: dict) -> str:
    return yaml.safe_dump(params, sort_keys=False, default_flow_style=None, width=100)


def load_params(path) -> dict:
    return load_yaml(path)


# --------------------------------------------------------------------------------------
# what each experiment produces (docs/contracts.md, "Per-figure datasets")
# --------------------------------------------------------------------------------------
def dataset_files(experiment: str, kind: str | None = None, root="results/data", params: dict | None = None
                  ) -> list[str]:
    """Datasets of one experiment; the Fourier comparison needs its resolved `params` (sources)."""
    kind = kind or KINDS[experiment]
    sources = params if kind == "fourier_compare" else None
    a, n = f"{root}/analytic", f"{root}/numeric"
    return {
        "fcr_theory": [f"{a}/fcr_{experiment}.nc"],
        "basin_rm": [f"{a}/basin_{experiment}.nc"],
        "fcr_compare": [f"{a}/fcr_{experiment}.nc", f"{n}/fcr_{experiment}.nc"],
        "basin_chart": [f"{a}/basin_{experiment}.nc", f"{n}/chart_{experiment}.nc"],
        "strobe": [f"{a}/basin_{experiment}.nc", f"{n}/strobe_{experiment}.nc"],
        "criteria": [f"{n}/criteria_{experiment}.nc"],
        "chart": [f"{n}/chart_{experiment}.nc"],
        "area_time": [],
        "erosion": [f"{root}/extras/erosion_analytic.nc", f"{root}/extras/erosion_numeric.nc"],
        "true_basin": [f"{root}/extras/true_basin_analytic.nc", f"{root}/extras/true_basin_numeric.nc"],
        "fourier_compare": [f"{root}/extras/fourier_{what}_{e}.nc" for what in ("fcr", "iou")
                            for e in (sources or {}).get(what, [])],
    }[kind]


# --------------------------------------------------------------------------------------
# helpers for the rule scripts
# --------------------------------------------------------------------------------------
def grid_axes(grid: dict):
    """1-D q0 and p0 axes of a resolved grid (endpoints included)."""
    nq, np_ = grid["n"]
    return (np.linspace(grid["q0"][0], grid["q0"][1], nq), np.linspace(grid["p0"][0], grid["p0"][1], np_))


def tile_slice(n: int, tiles: int, tile: int) -> slice:
    """Contiguous block `tile` (0-based) of `tiles` nearly equal blocks of range(n)."""
    if not 0 <= tile < tiles:
        raise ValueError(f"tile must lie in [0, {tiles}), got {tile}")
    edges = np.linspace(0, n, tiles + 1).round().astype(int)
    return slice(int(edges[tile]), int(edges[tile + 1]))


def redirect_output(log_path):
    """Send stdout and stderr of a rule script to its log file (line buffered)."""
    if log_path:
        os.makedirs(os.path.dirname(os.fspath(log_path)) or ".", exist_ok=True)
        fh = open(log_path, "w", buffering=1)
        sys.stdout = fh
        sys.stderr = fh
        return fh
    return None


def set_threads(n):
    """Limit numba's thread pool to the rule's `threads:` (no oversubscription under -j2)."""
    n = max(1, int(n))
    os.environ.setdefault("NUMBA_NUM_THREADS", str(n))
    try:
        import numba

        numba.set_num_threads(min(n, numba.config.NUMBA_NUM_THREADS))
    except Exception as exc:  # pragma: no cover - numba missing or pool already fixed
        print(f"warning: could not set numba threads to {n}: {exc}")


def call_api(fn, *args, **kwargs):
    """Call `fn`, dropping keyword arguments its signature does not accept (logged).

    Lets the rule scripts pass optional knobs (steps_per_cycle, threads, fourier, ...) to the
    theory/numerics functions whether or not a given version accepts them; what was dropped is
    printed to the rule's log and returned so it can be recorded in the dataset.
    """
    import inspect

    try:
        sig = inspect.signature(fn)
    except (TypeError, ValueError):
        return fn(*args, **kwargs), []
    accepts_var_kw = any(p.kind is inspect.Parameter.VAR_KEYWORD for p in sig.parameters.values())
    dropped = [] if accepts_var_kw else [k for k in kwargs if k not in sig.parameters]
    for k in dropped:
        print(f"note: {fn.__module__}.{fn.__name__} does not accept {k}={kwargs[k]!r}; library default used")
        kwargs.pop(k)
    return fn(*args, **kwargs), dropped


def write_params_file(path, params: dict, log_path=None):
    """Write results/params/{experiment}.yaml atomically (used by the `parameters` rule)."""
    import tempfile

    path = Path(path)
    text = (f"# Resolved parameters of {params['experiment']} ({params['kind']}), generated from the\n"
            "# configuration by the `parameters` rule; edit config/config.yaml, not this file.\n"
            + dump_params(params))
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    with os.fdopen(fd, "w") as fh:
        fh.write(text)
    os.chmod(tmp, 0o644)
    os.replace(tmp, path)
    if log_path:
        Path(log_path).parent.mkdir(parents=True, exist_ok=True)
        Path(log_path).write_text(f"wrote {path} (params sha256 {params_hash(params)})\n")
