#!/usr/bin/env python3
"""Sweeps on Dask: the SLIP over 64 grid points with 1 and 2 local workers, each point explored whole or
continuing its neighbour's families (speed-up, Dask's overhead per task against the work), and the 40 x 40
(k, w2) map of where hopping in place is stable.

    PYTHONPATH=build/python /usr/bin/python3 bench/sweep_bench.py [map [explore]]
"""
import os
import sys
import tempfile
import time

import hybridcont as hc
from hybridcont import sweeps


def timed(**kwargs):
    with tempfile.TemporaryDirectory() as work:
        t = time.perf_counter()
        table = hc.sweep("slip", out=os.path.join(work, "sweep"), progress=False, **kwargs)
        return time.perf_counter() - t, table


def work_alone(grid, **options):
    """The studies alone, one after another in this process (what the tasks compute)."""
    t = time.perf_counter()
    with tempfile.TemporaryDirectory() as work:
        for pid, values in sweeps.grid_points(sweeps.grid_values(grid)):
            opts = dict(options)
            opts["set"] = dict(values)
            hc.run("slip", out=os.path.join(work, pid), progress=False, threads=1, report=False, **opts)
    return time.perf_counter() - t


def main():
    grid = {"k": (20, 80, 8), "w2": (3, 7, 8)}
    alone = work_alone(grid)
    print("64 grid points, the studies alone (whole explorations): %.2f s" % alone)
    times = {}
    for strategy in ("explore", "continue"):
        for workers in (1, 2):
            times[strategy, workers], table = timed(grid=grid, workers=workers, strategy=strategy)
        print("strategy %s: Dask 1 worker %.2f s, 2 workers %.2f s (speed-up %.2f)"
              % (strategy, times[strategy, 1], times[strategy, 2], times[strategy, 1] / times[strategy, 2]))
    print("per task (explore): work %.1f ms, Dask + process start-up %.1f ms (1 worker)"
          % (1e3 * alone / 64, 1e3 * (times["explore", 1] - alone) / 64))
    print("continue against explore, 2 workers: %.2fx" % (times["explore", 2] / times["continue", 2]))
    if "map" in sys.argv[1:]:
        grid = {"k": (10, 160, 40), "w2": (2, 10, 40)}
        runs = [("continue", {"until": {"H": 2.0}})]
        if "explore" in sys.argv[1:]:
            runs.append(("explore", {"max_branches": 3, "until": {"H": 2.0}}))
        for strategy, options in runs:
            seconds, table = timed(grid=grid, workers=2, strategy=strategy, **options)
            hopping = table[table.family == "hopping in place"]
            print("40 x 40 map (k, w2), strategy %s %s: hopping in place stable at %d of 1600 points, %d rows: "
                  "%.1f s on 2 workers" % (strategy, options, int(hopping.stable.sum()), len(table), seconds))
            print("   ", table.strategy.str.split(" ").str[0].value_counts().to_dict())


if __name__ == "__main__":
    main()
