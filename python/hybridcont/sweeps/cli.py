"""`hybridcont sweep` (the tool runs `python -m hybridcont.sweeps`): the grid, where to run, and the options of
`hybridcont run`, each checked by the library as `run` checks it."""
import argparse
import os
import sys

import numpy as np

from .run import sweep


def _parse_grid(text):
    name, _, spec = text.partition("=")
    parts = spec.split(":")
    if not name or len(parts) != 3:
        raise argparse.ArgumentTypeError("--grid '%s': expected NAME=START:STOP:COUNT" % text)
    try:
        start, stop, count = float(parts[0]), float(parts[1]), int(parts[2])
    except ValueError:
        raise argparse.ArgumentTypeError("--grid '%s': START and STOP are numbers, COUNT a whole number" % text)
    if not (np.isfinite(start) and np.isfinite(stop)):
        raise argparse.ArgumentTypeError("--grid '%s': START and STOP must be finite" % text)
    return name, (start, stop, count)


def _parse_bound(text):
    """NAME=LO:HI (either side may be empty) as (name, (lo, hi)), None for an open side; checked by the library."""
    from .. import _hybridcont as native
    try:
        name, lower, upper = native.parse_bound("--bound", text)
    except ValueError as e:
        raise argparse.ArgumentTypeError(str(e))
    return name, (None if np.isinf(lower) else lower, None if np.isinf(upper) else upper)


def _parse_pairs(text, option):
    """NAME=VALUE or NAME=V1,V2,... as [(name, value)], checked by the library as `hybridcont run` checks it."""
    from .. import _hybridcont as native
    try:
        return native.parse_assignments(option, text)
    except ValueError as e:
        raise argparse.ArgumentTypeError(str(e))


def _parse_pair(text, option):
    pairs = _parse_pairs(text, option)
    if len(pairs) != 1:
        raise argparse.ArgumentTypeError("%s '%s': expected NAME=VALUE (one value)" % (option, text))
    return pairs[0]


def main(argv=None):
    """`hybridcont sweep` (the tool runs this module): the grid, where to run, and the options of `run`."""
    p = argparse.ArgumentParser(prog="hybridcont sweep", description="A study at every point of a parameter grid.")
    p.add_argument("model")
    p.add_argument("--grid", action="append", required=True, type=_parse_grid, help="NAME=START:STOP:COUNT")
    p.add_argument("--out", help="the sweep's folder (default results/MODEL-sweep)")
    p.add_argument("--scheduler", help="a Dask scheduler's address, tcp://HOST:PORT (default: a local cluster)")
    p.add_argument("--workers", type=int, help="local worker processes (default: one per core)")
    p.add_argument("--resume", action="store_true")
    p.add_argument("--overwrite", action="store_true")
    p.add_argument("--quiet", action="store_true")
    p.add_argument("--no-maps", action="store_true", help="draw no map figures")
    p.add_argument("--strategy", choices=("explore", "continue"), default="explore",
                   help="explore (the default): every grid point explored whole; continue: each grid point "
                        "continues its neighbour's families (faster; check it against explore on a coarse grid)")
    p.add_argument("--set", action="append", default=[], type=lambda t: _parse_pair(t, "--set"))
    p.add_argument("--until", action="append", default=[], type=lambda t: _parse_pair(t, "--until"))
    p.add_argument("--bound", action="append", default=[], type=_parse_bound, help="NAME=LO:HI")
    p.add_argument("--rtol", type=float)
    p.add_argument("--atol", type=float)
    p.add_argument("--max-branches", type=int)
    p.add_argument("--formulation", default="time")
    p.add_argument("--no-symmetry", action="store_true")
    p.add_argument("--family", action="append", dest="families",
                   help="map only this family (its name; repeatable): the table has its rows, each grid point "
                        "traces only what led to it")
    p.add_argument("--curves", help="a grid parameter P: on every grid line along P, one grid point continues its "
                                    "families' special points in (H, P); the report draws them over the ranges")
    p.add_argument("--monitor", action="append", default=[], type=lambda t: _parse_pairs(t, "--monitor"),
                   help="NAME=VALUE or NAME=V1,V2,...: locate where an observable takes the values (repeatable)")
    p.add_argument("--period-doubling", action="store_true")
    p.add_argument("--one-word", action="store_true")
    p.add_argument("--free", help="a parameter continued instead of H (with --fix; every grid point explored whole)")
    p.add_argument("--fix", type=lambda t: _parse_pair(t, "--fix"), help="NAME=VALUE held while --free varies")
    args = p.parse_args(argv)
    import warnings  # the command line says the sweep's warnings as notes, without Python's file and line
    warnings.showwarning = lambda message, *rest, **named: print("note: %s" % message, file=sys.stderr)
    monitors = {}
    for pairs in args.monitor:
        for name, value in pairs:
            monitors.setdefault(name, []).append(value)
    options = {"set": dict(args.set), "until": dict(args.until), "bound": dict(args.bound), "monitor": monitors,
               "rtol": args.rtol, "atol": args.atol, "max_branches": args.max_branches,
               "formulation": args.formulation, "no_symmetry": args.no_symmetry,
               "period_doubling": args.period_doubling, "one_word": args.one_word, "free": args.free,
               "fix": dict([args.fix]) if args.fix else None}
    options = {k: v for k, v in options.items() if not (v is None or v is False or (isinstance(v, dict) and not v))}
    out = args.out or os.path.join("results", os.path.basename(args.model).replace(".toml", "") + "-sweep")
    try:
        table = sweep(args.model, dict(args.grid), out, scheduler=args.scheduler, workers=args.workers,
                      resume=args.resume, overwrite=args.overwrite, progress=not args.quiet,
                      maps=not args.no_maps, strategy=args.strategy, curves=args.curves, families=args.families,
                      **options)
    except ValueError as e:
        print("error: %s" % e, file=sys.stderr)
        return 2
    except (RuntimeError, OSError) as e:  # a grid point's study stopped or not written (a full disk)
        print("error: %s\nthe grid points finished are kept in %s; --resume continues the sweep"
              % (e, os.path.abspath(out)), file=sys.stderr)
        return 1
    points = table["point"].nunique() if len(table) else 0
    print("%d grid points, %d rows: %s" % (points, len(table), os.path.join(os.path.abspath(out), "table.csv")))
    return 0
