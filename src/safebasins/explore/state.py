"""One state of the explorer, a well and a point of its sliders: checked, and written to and read
from a URL query (``?well=pendulum&F=0.05&Omega=0.9``) that the live page (``/``) and its static
picture (``/snapshot``) both read.

The well is any form :func:`safebasins.wells.spec_of` reads; in a query a named well is its
name and any other spec its JSON (``well={"name": "expression", "expression": "1 - cos(q)"}``).
"""
from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any
from urllib.parse import urlencode

from safebasins.core.checks import check_finite, check_nonnegative, check_positive, check_scalar
from safebasins.explore.analytic import Forcing
from safebasins.explore.ranges import WellRanges, well_ranges

__all__ = ["PARAMETERS", "forcing_of", "to_query", "from_query", "view"]

#: the sliders' parameters, in the order of the page (and of the query)
PARAMETERS = ("Omega", "F", "Psi", "xi_max", "damping")


def forcing_of(r: WellRanges, values: Mapping[str, Any] | None = None) -> Forcing:
    """The point ``values`` (a missing or None value: the well's default) on the well ``r``,
    checked: F >= 0, Omega > 0, Psi finite, xi_max in (0, E_b) (the slow flow is singular at the
    barrier energy), damping >= 0; ValueError naming the parameter."""
    v = {name: getattr(r, name).value for name in PARAMETERS}
    for name, value in (values or {}).items():
        if name not in PARAMETERS:
            raise ValueError(f"{name}: not a parameter of the explorer (give {', '.join(PARAMETERS)})")
        if value is not None:
            v[name] = value
    xi_max = check_scalar("xi_max", v["xi_max"], r.well.check_threshold)
    r.well.check_energy("xi_max", xi_max)
    return Forcing(F=check_scalar("F", v["F"], check_nonnegative),
                   Omega=check_scalar("Omega", v["Omega"], check_positive),
                   Psi=check_scalar("Psi", v["Psi"], check_finite), xi_max=xi_max,
                   damping=check_scalar("damping", v["damping"], check_nonnegative))


def _well_text(spec: dict[str, Any]) -> str:
    return spec["name"] if set(spec) == {"name"} else json.dumps(spec, separators=(",", ":"))


def to_query(r: WellRanges, f: Forcing) -> str:
    """The query string of the well ``r`` and the point ``f`` (numbers exact: ``repr`` of floats)."""
    return urlencode({"well": _well_text(r.spec), **{name: repr(float(getattr(f, name))) for name in PARAMETERS}})


def from_query(arguments: Mapping[str, Any]) -> tuple[object, dict[str, float]]:
    """``(well, values)`` of query ``arguments`` (a mapping of names to a value or a list of
    values, str or bytes: tornado's ``request.arguments``); the well is None when absent, its
    form not yet resolved (:func:`safebasins.explore.ranges.well_ranges` does that).  ValueError
    naming the key for an unknown key or a value that is not a number."""
    def one(key: str) -> str:
        value = arguments[key]
        if isinstance(value, (list, tuple)):
            value = value[-1]
        return value.decode() if isinstance(value, bytes) else str(value)

    well: object = None
    values: dict[str, float] = {}
    for key in arguments:
        if key == "well":
            text = one(key).strip()
            if text.startswith("{"):
                try:
                    well = json.loads(text)
                except json.JSONDecodeError as exc:
                    raise ValueError(f"well: cannot read {text!r} as JSON ({exc.msg})") from None
            else:
                well = text
        elif key in PARAMETERS:
            try:
                values[key] = float(one(key))
            except ValueError:
                raise ValueError(f"{key} must be a number, got {one(key)!r}") from None
        else:
            raise ValueError(f"{key}: not a key of the explorer's query (give well, {', '.join(PARAMETERS)})")
    return well, values


def view(well: object = "quartic", values: Mapping[str, Any] | None = None,
         arguments: Mapping[str, Any] | None = None) -> tuple[WellRanges, Forcing]:
    """The well and point of a page: those of the query ``arguments`` over the well ``well`` and the
    point ``values`` (of the command line); a query that names a well starts from its defaults."""
    q_well, q_values = from_query(arguments or {})
    r = well_ranges(well if q_well is None else q_well)
    return r, forcing_of(r, {**(values or {}), **q_values} if q_well is None else q_values)
