"""Datasets on disk: CF metadata (cf), provenance and netCDF writes (datasets), atomic file
writes (files), tile gathering (gather), value-by-value comparison (compare)."""
