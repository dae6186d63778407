#!/usr/bin/env python
"""Compare two ``results/data`` trees dataset by dataset, value by value.

    .venv/bin/python scripts/compare_results.py OLD/results/data NEW/results/data

Every ``*.nc`` below either root (tile parts under ``parts/`` excluded unless ``--parts``)
must exist in both trees; coordinates and data variables must be identical (names, dims,
dtypes, values bit for bit with NaN == NaN, and their attributes); global attributes must be
identical except the provenance ones (``safebasins.core.provenance.PROVENANCE_ATTRS``), which are
listed when they differ but do not fail the comparison. Exit status 1 on any difference.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from safebasins.io.compare import compare_trees


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("old", type=Path)
    ap.add_argument("new", type=Path)
    ap.add_argument("--parts", action="store_true", help="also compare the tile files under parts/")
    ap.add_argument("--quiet", action="store_true", help="print only differences and the summary")
    args = ap.parse_args(argv)
    report = compare_trees(args.old, args.new, parts=args.parts)
    for line in report.lines(verbose=not args.quiet):
        print(line)
    return 0 if report.identical else 1


if __name__ == "__main__":
    sys.exit(main())
