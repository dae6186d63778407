"""The package version: its one home (``safebasins.__version__``, the wheel's metadata and
CITATION.cff read it)."""
__version__ = "0.1.0"
