"""Provenance of API results that name a well: :func:`safebasins.core.provenance.api_provenance`
with the well's dataset attributes (:func:`safebasins.wells.well_attrs` of the resolved ``well``
argument; None is the quartic).  The public functions of theory, numerics and analysis use this
one decorator."""
from __future__ import annotations

import functools

from safebasins.core import provenance
from safebasins.wells import resolve_well, well_attrs

__all__ = ["api_provenance", "call_well_attrs"]


def call_well_attrs(well) -> dict:
    """Dataset attributes of a call's ``well`` argument (any form :func:`resolve_well` reads)."""
    return well_attrs(resolve_well(well))


#: ``@api_provenance``: the core's decorator with :func:`call_well_attrs`
api_provenance = functools.partial(provenance.api_provenance, well_attrs=call_well_attrs)
