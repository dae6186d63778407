"""Upper-bound cost of every experiment: trajectory-steps of its numerics (no early escape
assumed) and slow-flow evaluations of its analytic products (safebasins.pipeline.cost).

    .venv/bin/python scripts/estimate_cost.py                                  # config/config.yaml
    .venv/bin/python scripts/estimate_cost.py --configfile config/quick.yaml   # an overlay, as snakemake
    .venv/bin/python scripts/estimate_cost.py config/quick.yaml mine.yaml      # the same, positionally

Every file given is merged over config/config.yaml in order (as `snakemake --configfile`);
config/config.yaml itself may be named (merging it again changes nothing).  A bad file or key
is an error naming it (exit status 2), never a traceback.
"""
import argparse
import sys

from safebasins.pipeline.config import REPO_ROOT
from safebasins.pipeline.cost import guard, report
from safebasins.pipeline.plan import plan
from safebasins.pipeline.validation import ConfigError


def main(argv=None):
    ap = argparse.ArgumentParser(prog="estimate_cost.py", description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog="\n\n".join(__doc__.split("\n\n")[1:]))
    ap.add_argument("files", nargs="*", metavar="CONFIG", help="config files merged over config/config.yaml")
    ap.add_argument("--configfile", nargs="+", default=[], metavar="CONFIG",
                    help="config files merged over config/config.yaml (as snakemake's --configfile)")
    ap.add_argument("--cores", type=int, default=2, help="cores of the expected times (default 2)")
    args = ap.parse_args(argv)
    if args.cores < 1:
        ap.error(f"--cores must be >= 1, got {args.cores}")
    try:
        run = plan([str(REPO_ROOT / "config" / "config.yaml"), *args.files, *args.configfile])
        lines = report(run, cores=args.cores)
        try:
            lines.append(guard(run, cores=args.cores))
        except ConfigError as exc:    # over budget: say so, the table still stands
            lines.append(f"the pipeline would refuse to start: {exc}")
    except (ConfigError, ValueError) as exc:
        print(f"estimate_cost.py: error: {exc}", file=sys.stderr)
        return 2
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
