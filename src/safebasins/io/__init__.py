"""Datasets on disk: CF metadata (cf), provenance and netCDF writes (datasets), netCDF reads and
writes whose errors name the file and the cause (netcdf), atomic file writes (files), tile
gathering (gather), value-by-value comparison (compare)."""
