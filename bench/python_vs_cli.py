#!/usr/bin/env python3
"""The Python call against the command line on the SLIP: `hybridcont run slip` (a process: start-up, the
study, the results folder with report.html) and `hybridcont.run("slip")` (in a running interpreter: the study,
the same folder and report, the Study object), alternated, nine of each; minimum and median wall times.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_vs_cli.py build/hybridcont
"""
import statistics
import subprocess
import sys
import tempfile
import time

import hybridcont as hc


def main(tool):
    with tempfile.TemporaryDirectory() as work:
        def cli():
            t = time.perf_counter()
            subprocess.run([tool, "run", "slip", "--quiet", "--out", work + "/cli", "--overwrite"], check=True,
                           stdout=subprocess.DEVNULL)
            return time.perf_counter() - t

        def python():
            t = time.perf_counter()
            hc.run("slip", out=work + "/py", overwrite=True, progress=False)
            return time.perf_counter() - t

        cli(), python()  # warm: the page cache, the compiled-model cache
        a, b = [], []
        for _ in range(9):
            a.append(cli())
            b.append(python())
    print("command line  min %.3f s  median %.3f s" % (min(a), statistics.median(a)))
    print("python        min %.3f s  median %.3f s" % (min(b), statistics.median(b)))
    print("overhead      min %+.1f %%  median %+.1f %%" % (100 * (min(b) / min(a) - 1),
                                                         100 * (statistics.median(b) / statistics.median(a) - 1)))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "build/hybridcont")
