#!/usr/bin/env python3
"""Screenshots of report.html for docs/figures/: the SLIP, the bipedal model and the bouncing rod, each with the
first stable point of its first physical family selected (its orbit drawn, its multipliers shown).

    /usr/bin/python3 scripts/report-screenshots.py build/hybridcont docs/figures
"""
import os
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
from browser import Browser, wait_for  # noqa: E402

MODELS = [("slip", "slip"), ("bipedal-slip", "bipedal-slip"), ("bouncing-rod", "bouncing-rod")]


def main(tool, folder):
    with tempfile.TemporaryDirectory() as work:
        for model, name in MODELS:
            out = os.path.join(work, name)
            subprocess.run([tool, "run", model, "--out", out, "--quiet"], check=True, stdout=subprocess.DEVNULL)
            browser = Browser("file://" + os.path.join(out, "report.html"))
            try:
                wait_for(browser, "document.readyState === 'complete' && !!document.querySelector('#diagram .scatterlayer')")
                # The first physical point that is stable, else the first physical one, selected by its table row
                # of families and then by the point itself.
                browser.evaluate("""(() => {
                    const study = JSON.parse(document.getElementById('study-data').textContent);
                    const branchColumn = [...document.querySelectorAll('#families thead th')]
                        .findIndex(th => th.textContent === 'branch');
                    for (const b of study.branches) {
                        let i = b.stable.indexOf(true);
                        if (i < 0) i = b.physical.indexOf(true);
                        if (i < 0) continue;
                        const row = [...document.querySelectorAll('#families tbody tr')]
                            .find(r => r.cells[branchColumn].textContent.startsWith(String(b.id)));
                        if (row) row.click();
                        return;
                    }
                })()""")
                time.sleep(0.6)
                browser.screenshot(os.path.join(folder, "report-" + name + ".png"))
                if browser.errors():
                    raise RuntimeError(name + ": " + "; ".join(browser.errors()))
            finally:
                browser.close()
            print("report-" + name + ".png")


if __name__ == "__main__":
    main(os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2]))
