"""python -m irpol.dataset SPEC.toml [--scheduler ADDRESS] [--workers N]"""

from __future__ import annotations

import argparse
import sys

from .runner import run
from .spec import SpecError


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m irpol.dataset",
                                     description="Runs a sweep spec (docs/design.md §2.7) on Dask.")
    parser.add_argument("spec", help="the sweep spec TOML")
    parser.add_argument("--scheduler", help="address of a running Dask scheduler "
                        "(default: a LocalCluster on this machine)")
    parser.add_argument("--workers", type=int, help="LocalCluster worker processes (default 2)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    args = parser.parse_args(argv)
    try:
        summary = run(args.spec, scheduler=args.scheduler, workers=args.workers,
                      progress=not args.no_progress)
    except (SpecError, OSError) as error:
        print(f"irpol.dataset: error: {error}", file=sys.stderr)
        return 2
    print(f"{summary.items} items: {summary.skipped} already done, {summary.ok} ok, "
          f"{summary.failed} failed, in {summary.seconds:.1f} s")
    return 1 if summary.failed else 0


if __name__ == "__main__":
    sys.exit(main())
