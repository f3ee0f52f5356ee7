"""`hybridcont sweep` (the tool runs `python -m hybridcont.sweeps`): the grid, where to run, and the options of
`hybridcont run`, each checked by the library as `run` checks it."""
import argparse
import os
import sys

import numpy as np

from .grid import MAX_GRID_POINTS
from .run import sweep


def _positive_count(text):
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError("'%s' is not a whole number" % text)
    if value < 1:
        raise argparse.ArgumentTypeError("'%s': at least 1" % text)
    return value


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


def _study_options():
    """The options of `hybridcont run` a sweep applies at every grid point, as the library declares them."""
    from .. import _hybridcont as native
    return [spec for spec in native.study_options() if spec["sweep"]]


def _add_study_options(parser):
    """Each option of `hybridcont run` that a sweep applies at every grid point, as `run` takes it (its flag,
    help and value form from the library's declaration; the texts checked by the library as `run` checks them)."""
    for spec in _study_options():
        if spec["switch"]:
            parser.add_argument(spec["flag"], action="store_true", dest=spec["field"], help=spec["flag_help"])
        else:
            parser.add_argument(spec["flag"], action="append", dest=spec["field"], metavar=spec["value_name"],
                                help=spec["flag_help"])


def _study_keywords(args, parser):
    """The parsed study options as `hybridcont.run`'s keyword arguments; a refused text ends the command with
    the library's message (exit 2)."""
    from .. import _hybridcont as native
    options = {}
    for spec in _study_options():
        value = getattr(args, spec["field"])
        if value in (None, False):
            continue
        if spec["switch"]:
            options[spec["keyword"]] = True
            continue
        try:
            options[spec["keyword"]] = native.parse_option(spec["field"], value)
        except ValueError as e:
            parser.error(str(e))
    return options


def main(argv=None):
    """`hybridcont sweep` (the tool runs this module): the grid, where to run, and the options of `run`."""
    p = argparse.ArgumentParser(prog="hybridcont sweep", description="A study at every point of a parameter grid.")
    p.add_argument("model")
    p.add_argument("--grid", action="append", required=True, type=_parse_grid, help="NAME=START:STOP:COUNT")
    p.add_argument("--out", help="the sweep's folder (default results/MODEL-sweep)")
    p.add_argument("--scheduler", help="a Dask scheduler's address, tcp://HOST:PORT (default: a local cluster)")
    p.add_argument("--workers", type=_positive_count, help="local worker processes (default: one per core)")
    p.add_argument("--max-grid-points", type=_positive_count, default=MAX_GRID_POINTS,
                   help="the most grid points the sweep computes, each a whole study (default %d): a larger grid "
                        "is refused before anything runs" % MAX_GRID_POINTS)
    p.add_argument("--resume", action="store_true")
    p.add_argument("--overwrite", action="store_true")
    p.add_argument("--quiet", action="store_true")
    p.add_argument("--no-maps", action="store_true", help="draw no map figures")
    p.add_argument("--strategy", choices=("explore", "continue"), default="explore",
                   help="explore (the default): every grid point explored whole; continue: each grid point "
                        "continues its neighbour's families (faster; check it against explore on a coarse grid)")
    p.add_argument("--family", action="append", dest="families",
                   help="map only this family (its name; repeatable): the table has its rows, each grid point "
                        "traces only what led to it")
    p.add_argument("--curves", help="a grid parameter P: on every grid line along P, one grid point continues its "
                                    "families' special points in (H, P); the report draws them over the ranges")
    _add_study_options(p)
    args = p.parse_args(argv)
    import signal  # a SIGTERM (the `hybridcont sweep` command killed) ends the sweep as Ctrl-C does: workers closed

    def _terminate(signum, frame):
        raise KeyboardInterrupt
    signal.signal(signal.SIGTERM, _terminate)
    names = [name for name, _ in args.grid]
    for name in names:
        if names.count(name) > 1:
            p.error("--grid %s: given twice; give each grid parameter once" % name)
    import warnings  # the command line says the sweep's warnings as notes, without Python's file and line
    warnings.showwarning = lambda message, *rest, **named: print("note: %s" % message, file=sys.stderr)
    options = _study_keywords(args, p)
    out = args.out or os.path.join("results", os.path.basename(args.model).replace(".toml", "") + "-sweep")
    try:
        table = sweep(args.model, dict(args.grid), out, scheduler=args.scheduler, workers=args.workers,
                      resume=args.resume, overwrite=args.overwrite, progress=not args.quiet,
                      maps=not args.no_maps, strategy=args.strategy, curves=args.curves, families=args.families,
                      max_grid_points=args.max_grid_points, **options)
    except ValueError as e:
        print("error: %s" % e, file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("error: interrupted; the grid points finished are kept in %s; --resume continues the sweep"
              % os.path.abspath(out), file=sys.stderr)
        return 130
    except (RuntimeError, OSError) as e:  # a grid point's study stopped or not written (a full disk)
        print("error: %s\nthe grid points finished are kept in %s; --resume continues the sweep"
              % (e, os.path.abspath(out)), file=sys.stderr)
        return 1
    points = table["point"].nunique() if len(table) else 0
    print("%d grid points, %d rows: %s" % (points, len(table), os.path.join(os.path.abspath(out), "table.csv")))
    print(found_line(table, points))
    return 0


def found_line(table, points):
    """What the sweep found, a line per family: at how many grid points it has physical orbits and at how many
    stable ones ("  hopping in place: physical at 16 of 16 grid points, stable at 12"); "found: no family" where
    no grid point holds one."""
    if not len(table) or "family" not in table.columns:
        return "found: no family"
    said = []
    for family, rows in table[table.exists.astype(bool)].groupby("family", sort=False):
        physical = rows[rows.physical.astype(bool)]["point"].nunique()
        stable = rows[rows.stable.astype(bool)]["point"].nunique()
        said.append("  %s: physical at %d of %d grid points, stable at %d" % (family, physical, points, stable))
    return "found:\n" + "\n".join(said) if said else "found: no family"
