"""Provenance of API results that name a well: :func:`safebasins.core.provenance.api_provenance`
with the well's dataset attributes (:func:`safebasins.wells.well_attrs` of the resolved ``well``
argument; None is the quartic).  The public functions of theory, numerics and analysis use this
one decorator."""
from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar

from safebasins.core import provenance
from safebasins.wells import resolve_well, well_attrs
from safebasins.wells.base import WellLike

__all__ = ["api_provenance", "call_well_attrs"]

F = TypeVar("F", bound=Callable[..., Any])


def call_well_attrs(well: WellLike) -> dict[str, Any]:
    """Dataset attributes of a call's ``well`` argument (any form :func:`resolve_well` reads)."""
    return well_attrs(resolve_well(well))


def api_provenance(fn: F) -> F:
    """``@api_provenance``: the core's decorator with :func:`call_well_attrs`."""
    return provenance.api_provenance(fn, well_attrs=call_well_attrs)
