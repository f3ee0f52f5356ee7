"""report.html in a real browser: headless Chromium opens the SLIP's report from file:// (no network), no script
fails or logs an error, a click on a point of a physical family (a mouse event at that point's pixel, through
the browser) shows the point's class, its orbit animated as the model draws it and its Floquet multipliers on
the unit circle, and a row of the special points' table selects its point. The browser is driven over the DevTools protocol on a pipe (Chromium's
--remote-debugging-pipe: JSON messages separated by NUL bytes on file descriptors 3 and 4).

Environment: HYBRIDCONT_BIN (the built tool), CHROMIUM (default: chromium on PATH). Screenshots of the page
go to HYBRIDCONT_REPORT_SCREENSHOTS if set (docs/figures/ holds the README's).
"""
import base64
import json
import os
import shutil
import subprocess
import tempfile
import time

import pytest

TOOL = os.environ.get("HYBRIDCONT_BIN", "build/hybridcont")
CHROMIUM = os.environ.get("CHROMIUM") or shutil.which("chromium") or shutil.which("chromium-browser")


class Browser:
    """One headless Chromium page, driven over the DevTools protocol on a pipe."""

    def __init__(self, url):
        to_browser_read, self.to_browser = os.pipe()
        self.from_browser, from_browser_write = os.pipe()
        self.profile = tempfile.mkdtemp(prefix="hybridcont-chromium-")
        def pipes_on_3_and_4():
            # Copies first, so that dup2 never meets its own descriptor (and clears close-on-exec).
            read, write = os.dup(to_browser_read), os.dup(from_browser_write)
            os.dup2(read, 3)
            os.dup2(write, 4)

        self.process = subprocess.Popen(
            [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--remote-debugging-pipe",
             "--user-data-dir=" + self.profile, "--window-size=1400,1100", "about:blank"],
            close_fds=False, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, preexec_fn=pipes_on_3_and_4)
        os.close(to_browser_read)
        os.close(from_browser_write)
        self.buffer = b""
        self.next_id = 0
        self.events = []
        target = self.call("Target.createTarget", {"url": "about:blank"})["targetId"]
        self.session = self.call("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        for domain in ("Runtime", "Log", "Page"):
            self.call(domain + ".enable", session=True)
        self.call("Page.navigate", {"url": url}, session=True)

    def send(self, method, params=None, session=False):
        self.next_id += 1
        message = {"id": self.next_id, "method": method, "params": params or {}}
        if session:
            message["sessionId"] = self.session
        os.write(self.to_browser, json.dumps(message).encode() + b"\0")
        return self.next_id

    def receive(self, timeout=30):
        deadline = time.time() + timeout
        while b"\0" not in self.buffer:
            if time.time() > deadline:
                raise TimeoutError("no answer from the browser")
            chunk = os.read(self.from_browser, 1 << 16)
            if not chunk:
                raise RuntimeError("the browser closed its pipe")
            self.buffer += chunk
        message, self.buffer = self.buffer.split(b"\0", 1)
        return json.loads(message)

    def call(self, method, params=None, session=False):
        wanted = self.send(method, params, session)
        while True:
            message = self.receive()
            if message.get("id") == wanted:
                if "error" in message:
                    raise RuntimeError(method + ": " + json.dumps(message["error"]))
                return message.get("result", {})
            self.events.append(message)

    def evaluate(self, expression):
        result = self.call("Runtime.evaluate", {"expression": expression, "returnByValue": True, "awaitPromise": True},
                           session=True)
        if "exceptionDetails" in result:
            raise RuntimeError(json.dumps(result["exceptionDetails"]))
        return result["result"].get("value")

    def click(self, x, y):
        for kind in ("mouseMoved", "mousePressed", "mouseReleased"):
            self.call("Input.dispatchMouseEvent",
                      {"type": kind, "x": x, "y": y, "button": "left", "clickCount": 1}, session=True)

    def errors(self):
        """Uncaught exceptions, console errors and error log entries seen so far."""
        found = []
        for e in self.events:
            method, params = e.get("method"), e.get("params", {})
            if method == "Runtime.exceptionThrown":
                found.append(json.dumps(params.get("exceptionDetails", {}))[:500])
            elif method == "Runtime.consoleAPICalled" and params.get("type") in ("error", "assert"):
                found.append(json.dumps(params.get("args", []))[:500])
            elif method == "Log.entryAdded" and params.get("entry", {}).get("level") == "error":
                found.append(params["entry"].get("text", "")[:500])
        return found

    def screenshot(self, path):
        data = self.call("Page.captureScreenshot", {"format": "png"}, session=True)["data"]
        with open(path, "wb") as f:
            f.write(base64.b64decode(data))

    def close(self):
        self.process.kill()
        self.process.wait()
        os.close(self.to_browser)
        os.close(self.from_browser)
        shutil.rmtree(self.profile, ignore_errors=True)


def wait_for(browser, expression, timeout=30):
    deadline = time.time() + timeout
    while time.time() < deadline:
        if browser.evaluate(expression):
            return
        time.sleep(0.1)
    raise TimeoutError(expression)


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
        # The page fetches nothing: every script is inline.
        assert browser.evaluate("[...document.scripts].every(s => !s.src)")
        # A point of hopping in place (branch 2) where it is stable, at its pixel on the screen.
        where = browser.evaluate("""(() => {
            const gd = document.getElementById('diagram');
            const trace = gd.data.findIndex(t => t.name === 'hopping in place · stable');
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
