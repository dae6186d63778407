"""Potential wells: V, dV, H0, barriers, turning points and action-angle data (wells.base)."""
from safebasins.wells.base import Well

__all__ = ["Well"]
