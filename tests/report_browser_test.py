"""report.html in a real browser: headless Chromium opens the SLIP's report from file:// (no network), no script
fails or logs an error, a click on a point of a physical family (a mouse event at that point's pixel, through
the browser) shows the point's class, its orbit animated as the model draws it and its Floquet multipliers on
the unit circle, and a row of the special points' table selects its point. The browser is driven over the DevTools protocol on a pipe (tests/browser.py).

Environment: HYBRIDCONT_BIN (the built tool), CHROMIUM (default: chromium on PATH). Screenshots of the page
go to HYBRIDCONT_REPORT_SCREENSHOTS if set (docs/figures/ holds the README's).
"""
import os
import subprocess
import sys
import time

import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from browser import CHROMIUM, Browser, wait_for  # noqa: E402

TOOL = os.environ.get("HYBRIDCONT_BIN", "build/hybridcont")


@pytest.fixture(scope="module")
def slip_report(tmp_path_factory):
    out = tmp_path_factory.mktemp("report") / "slip"
    subprocess.run([TOOL, "run", "slip", "--out", str(out), "--quiet", "--no-plots", "--threads", "1"], check=True,
                   stdout=subprocess.DEVNULL)
    report = out / "report.html"
    assert report.exists()
    return report


@pytest.mark.skipif(CHROMIUM is None, reason="no chromium (sh scripts/install-deps.sh installs it)")
def test_report_opens_offline_and_a_click_shows_the_orbit(slip_report):
    browser = Browser(slip_report.as_uri())
    try:
        wait_for(browser, "document.readyState === 'complete' && !!document.querySelector('#diagram .scatterlayer')")
        assert browser.errors() == []
        # Before a point is chosen, no empty orbit frame is on the screen.
        assert browser.evaluate("getComputedStyle(document.getElementById('orbit')).display") == "none"
        # The page fetches nothing: every script is inline.
        assert browser.evaluate("[...document.scripts].every(s => !s.src)")
        # A point of hopping in place (branch 2) where it is stable, at its pixel on the screen.
        where = browser.evaluate("""(() => {
            const gd = document.getElementById('diagram');
            const trace = gd.data.findIndex(t => t.name === 'hopping in place' && t.meta === 'stable');
            const t = gd.data[trace];
            const i = t.x.findIndex((v, k) => v !== null && t.x[k + 3] !== null && k > 2);
            const xa = gd._fullLayout.xaxis, ya = gd._fullLayout.yaxis;
            const box = gd.querySelector('.draglayer .nsewdrag').getBoundingClientRect();
            return {x: box.left + xa.l2p(t.x[i]), y: box.top + ya.l2p(t.y[i]), index: t.customdata[i][1]};
        })()""")
        browser.click(where["x"], where["y"])
        wait_for(browser, "document.getElementById('point').dataset.branch === '2'")
        shown = browser.evaluate("""({
            index: Number(document.getElementById('point').dataset.index),
            text: document.getElementById('point').innerText,
            multipliers: document.querySelectorAll('#multipliers .scatterlayer .trace:nth-child(2) .point').length,
            circle: !!document.querySelector('#multipliers .scatterlayer .trace path.js-line'),
            orbit_shown: !document.getElementById('orbit').hidden,
            frames: Number(document.getElementById('orbit').dataset.frames),
        })""")
        assert abs(shown["index"] - where["index"]) <= 1, shown
        assert "asymptotically stable" in shown["text"] or "neutrally stable" in shown["text"], shown["text"]
        assert shown["multipliers"] == 2 and shown["circle"], shown
        # The orbit animated as the model draws it: frames of one period, drawn (pixels that are not blank).
        assert shown["orbit_shown"] and shown["frames"] >= 40, shown
        time.sleep(0.3)
        painted = browser.evaluate("""(() => {
            const c = document.getElementById('orbit');
            const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
            let n = 0;
            for (let k = 3; k < d.length; k += 4) n += d[k] > 0;
            return n;
        })()""")
        assert painted > 200, painted
        # A row of the special points' table selects its point.
        browser.evaluate("[...document.querySelectorAll('#special-points tbody tr')]"
                         ".find(r => r.cells[0].textContent === 'PD4').click()")
        wait_for(browser, "document.getElementById('point').innerText.includes('hopping in place')")
        assert browser.errors() == []
        screenshots = os.environ.get("HYBRIDCONT_REPORT_SCREENSHOTS")
        if screenshots:
            browser.screenshot(os.path.join(screenshots, "report-slip.png"))
    finally:
        browser.close()


@pytest.mark.skipif(CHROMIUM is None, reason="no chromium (sh scripts/install-deps.sh installs it)")
def test_parameter_plane_shades_where_families_are_physical_and_stable(tmp_path):
    """`--curves k`: the plane (k, H) with the curves of the special points and the regions between them; hopping
    in place is stable between its PD4 curve (below) and its SB5 curve (above) at every k of both."""
    out = tmp_path / "slip-k"
    subprocess.run([TOOL, "run", "slip", "--curves", "k", "--out", str(out), "--quiet", "--threads", "1"], check=True,
                   stdout=subprocess.DEVNULL)
    browser = Browser((out / "report.html").as_uri())
    try:
        wait_for(browser, "document.readyState === 'complete' && !!document.querySelector('#plane .scatterlayer')")
        assert browser.errors() == []
        assert browser.evaluate("document.getElementById('plane-panel').hidden") is False
        names = browser.evaluate("[...document.querySelectorAll('#plane .legendtext')].map(t => t.textContent)")
        assert "hopping in place · stable" in names, names
        assert "PD4 · period-doubling (hopping in place)" in names, names
        assert any(n.startswith("SB5 · branch-point") for n in names), names
        # The stable region of hopping in place, read back from the data the page drew: its lower edge is the
        # PD4 curve, its upper edge the SB5 curve, over the same k.
        check = browser.evaluate("""(() => {
            const plane = JSON.parse(document.getElementById('study-data').textContent).plane;
            const region = plane.regions.find(r => r.family === 'hopping in place' && r.kind === 'stable');
            const curve = (label) => plane.curves.find(c => c.label === label).points;
            const onCurve = (q, pts) => pts.some(p => p[0] === q[0] && p[1] === q[1]);
            const pd = curve('PD4'), sb = curve('SB5');
            const n = region.polygon.length;
            const lower = region.polygon.slice(0, n / 2), upper = region.polygon.slice(n / 2);
            return {n, lower: lower.every(q => onCurve(q, pd)), upper: upper.every(q => onCurve(q, sb)),
                    fills: document.querySelectorAll('#plane .fills path').length};
        })()""")
        assert check["n"] > 100 and check["lower"] and check["upper"], check
        assert check["fills"] >= 3, check
    finally:
        browser.close()
