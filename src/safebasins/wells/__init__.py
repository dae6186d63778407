"""Potential wells: V, dV, H0, barriers, turning points and action-angle data (wells.base).

``QUARTIC`` is the paper's well (closed forms, wells.quartic); ``cubic()`` the escape equation
V = q^2/2 - q^3/3, ``polynomial(coefficients)`` any polynomial well, ``expression(text)`` any
well written in q (``"1 - cos(q)"``; numeric action-angle: wells.numeric, wells.polynomial,
wells.expression).  Every well owns one compiled form for the engines (``Well.compiled``).

A well is named in one of these forms, the same in the config (``well:``), the command line
(``--well``) and the API (``well=``):

* a name of :data:`NAMED_WELLS` (``"quartic"``, ``"cubic"``, ``"pendulum"``, ``"sech2"``, ``"morse"``);
* ``{"polynomial": [c0, c1, c2, ...]}`` for V = sum c_k q^k;
* ``{"expression": "1 - cos(q)"}`` for any formula in q (sympy);
* either mapping may add ``"tol"``: the relative accuracy of its action-angle interpolants
  (default 1e-13, in [1e-15, 1e-2]; :class:`~safebasins.wells.numeric.NumericWell`), for a formula
  whose own rounding does not allow 1e-13 (the construction says so);
* a :class:`Well` object (e.g. a :class:`~safebasins.wells.numeric.NumericWell` of your own
  numba-compilable V, dV).

:func:`resolve_well` is the one place that turns any of them into a :class:`Well`.
"""
from __future__ import annotations

import functools

from collections.abc import Callable
from typing import Any

import numpy as np

from safebasins.wells.base import Well, WellLike
from safebasins.wells.quartic import FOURIER_VARIANTS, QUARTIC, QuarticWell
# (bound here, after the submodule import, so the package attribute is the function)
from safebasins.wells.polynomial import cubic, polynomial
from safebasins.wells.expression import expression
from safebasins.wells.well_shape import check_options

__all__ = ["Well", "QuarticWell", "QUARTIC", "NAMED_WELLS", "resolve_well", "from_spec", "from_attrs", "spec_attrs",
           "well_attrs", "spec_of", "cubic", "polynomial", "expression", "describe_forms"]

#: named wells: name -> (builder, one-line description).  Adding a named well is one line here: the
#: config schema, the command line and the docs read this table; an expression compiles for the
#: CPU and the GPU engines by itself (wells.expression).
NAMED_WELLS: dict[str, tuple[Callable[[], Well], str]] = {
    "quartic": (lambda: QUARTIC, "the paper's truncated quartic V = q^2/2 - q^4/4 (closed forms), barriers q = +-1"),
    "cubic": (cubic, "the escape equation V = q^2/2 - q^3/3, one barrier at q = 1 (E_b = 1/6)"),
    "pendulum": (lambda: expression("1 - cos(q)", name="pendulum"),
                 "the pendulum / ship roll V = 1 - cos q, barriers q = +-pi (E_b = 2)"),
    "sech2": (lambda: expression("tanh(q)**2", name="sech2"),
              "the Poschl-Teller well V = 1 - sech^2 q = tanh^2 q, open at infinity on both sides (E_b = 1)"),
    "morse": (lambda: expression("(1 - exp(-q))**2", name="morse"),
              "the Morse well V = (1 - exp(-q))^2, open at q -> +inf (E_b = 1), closed on the left"),
}
SPEC_KEYS = ("polynomial", "expression")
#: the optional key of a polynomial or expression spec (NumericWell's tol)
TOL_KEY = "tol"


def describe_forms() -> str:
    """The accepted well forms, for error messages and help texts."""
    return (f"a name ({', '.join(NAMED_WELLS)}), {{'polynomial': [c0, c1, c2, ...]}}, "
            "{'expression': '<formula in q>'} (either optionally with 'tol': 1e-11) or a safebasins.wells.Well")


def _tol_of(spec: Any) -> dict[str, Any]:
    """``{"tol": float}`` of a spec mapping that has the key, checked (ValueError naming ``well``), else ``{}``."""
    if TOL_KEY not in spec:
        return {}
    try:
        tol = check_options(tol=spec[TOL_KEY])[0]
    except ValueError as exc:
        raise ValueError(f"well: {exc}") from None
    return {TOL_KEY: tol}


def spec_of(config_value: Any) -> dict[str, Any]:
    """Resolved spec of a well form: ``{"name": "cubic"}``, ``{"name": "polynomial",
    "coefficients": [...]}`` or ``{"name": "expression", "expression": "..."}`` (the last two with
    ``"tol"`` when given); ValueError naming ``well`` for anything else."""
    if isinstance(config_value, str):
        if config_value not in NAMED_WELLS:
            raise ValueError(f"well: unknown well {config_value!r}; give {describe_forms()}")
        return {"name": config_value}
    if isinstance(config_value, dict):
        if "name" in config_value:                       # already resolved
            name = config_value["name"]
            if name in SPEC_KEYS:
                if name not in config_value:
                    key = "coefficients" if name == "polynomial" else name
                    if key not in config_value:
                        raise ValueError(f"well: spec {config_value!r} lacks {key!r}")
                return spec_of({name: config_value["coefficients" if name == "polynomial" else name],
                                **{k: config_value[k] for k in (TOL_KEY,) if k in config_value}})
            return spec_of(name)
        keys = [k for k in config_value if k != TOL_KEY]
        if len(keys) == 1:
            key = keys[0]
            value = config_value[key]
            if key == "polynomial":
                try:
                    coefficients = [float(c) for c in value]
                except (TypeError, ValueError):
                    raise ValueError("well: polynomial coefficients must be a list of numbers, got "
                                     f"{value!r}") from None
                return {"name": "polynomial", "coefficients": coefficients, **_tol_of(config_value)}
            if key == "expression":
                if not isinstance(value, str):
                    raise ValueError(f"well: expression must be a string in q, got {value!r}")
                return {"name": "expression", "expression": value, **_tol_of(config_value)}
    raise ValueError(f"well: {config_value!r} is not a well; give {describe_forms()}")


@functools.lru_cache(maxsize=64)
def _build(name: str, payload: Any, tol: Any = None) -> Any:
    extra = {} if tol is None else {"tol": tol}
    if name == "polynomial":
        return polynomial(list(payload), **extra)
    if name == "expression":
        return expression(payload, **extra)
    return NAMED_WELLS[name][0]()


def from_spec(spec: Any, fourier: str | None = None) -> Well:
    """The well of a spec (resolved, or any form :func:`spec_of` reads); ``fourier`` selects the
    quartic's first harmonic ("paper" is an error with any other well).  Built once per spec and kept."""
    s = spec_of(spec)
    name = s["name"]
    if name == "quartic":
        return resolve_well(None, fourier)
    payload = tuple(s["coefficients"]) if name == "polynomial" else s.get("expression")
    return resolve_well(_build(name, payload, s.get(TOL_KEY)), fourier)


def resolve_well(well: WellLike = None, fourier: str | None = None) -> Well:
    """The one resolver of a ``well=`` argument: None (the paper's quartic), a name, a spec dict
    or a :class:`Well` object (module docstring).  ``fourier`` ("paper" | "exact") selects the
    quartic's G (eq 20 as printed or exact); every other well carries its exact first harmonic
    ("paper" is an error there)."""
    if fourier is not None and fourier not in FOURIER_VARIANTS:
        raise ValueError(f"fourier must be one of {FOURIER_VARIANTS}, got {fourier!r}")
    if well is None:
        return QUARTIC if fourier in (None, "paper") else QuarticWell(fourier)
    if isinstance(well, (str, dict)):
        return from_spec(well, fourier)
    if not isinstance(well, Well):
        raise ValueError(f"well must be {describe_forms()}; got {well!r}")
    if isinstance(well, QuarticWell):
        return well if fourier is None or fourier == well.fourier else QuarticWell(fourier)
    if fourier == "paper":
        raise ValueError(f"fourier='paper' selects the quartic's truncated first harmonic (eq 20); the {well.name} "
                         "well uses its exact first harmonic: leave fourier out (or 'exact')")
    return well


def spec_attrs(spec: Any) -> dict[str, Any]:
    """Dataset attributes naming a well spec: ``well`` and, for a polynomial, ``well_coefficients``,
    for an expression, ``well_expression``; ``well_tol`` where the spec gives ``tol``."""
    s = spec_of(spec)
    out = {"well": s["name"]}
    if s["name"] == "polynomial":
        out["well_coefficients"] = [float(c) for c in s["coefficients"]]
    if s["name"] == "expression":
        out["well_expression"] = s["expression"]
    if TOL_KEY in s:
        out["well_tol"] = s[TOL_KEY]
    return out


def well_attrs(well: Well) -> dict[str, Any]:
    """Dataset attributes naming a well object (:func:`spec_attrs` of its spec)."""
    spec = well.spec()
    if spec["name"] not in NAMED_WELLS and spec["name"] not in SPEC_KEYS:
        return {"well": spec["name"]}             # a user's well object: named, not rebuildable
    return spec_attrs(spec)


def from_attrs(attrs: Any) -> Well:
    """The well a dataset was made with (its :func:`spec_attrs` attributes)."""
    if not hasattr(attrs, "get"):
        raise ValueError(f"attrs must be a dataset's attributes (a mapping), got {type(attrs).__name__}")
    if "well" not in attrs:
        raise ValueError("the dataset names no well (attribute 'well'): pass well= explicitly")
    name = attrs["well"]
    if not isinstance(name, str):
        raise ValueError(f"the dataset's attribute 'well' must be a well's name, got {name!r}: pass well= explicitly")
    needs = {"polynomial": "well_coefficients", "expression": "well_expression"}.get(name)
    if needs is not None and needs not in attrs:
        raise ValueError(f"the dataset's well is {name!r} but it lacks the attribute {needs!r} that defines it: "
                         "pass well= explicitly")
    tol = {TOL_KEY: float(attrs["well_tol"])} if "well_tol" in attrs else {}
    if name == "polynomial":
        return from_spec({"polynomial": [float(c) for c in np.atleast_1d(attrs["well_coefficients"])], **tol})
    if name == "expression":
        return from_spec({"expression": str(attrs["well_expression"]), **tol})
    if name not in NAMED_WELLS:
        raise ValueError(f"the dataset was made with the well {name!r}, which is not a named well: pass well= "
                         "explicitly")
    return from_spec(name)
