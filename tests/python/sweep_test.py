"""Sweeps on a real Dask cluster: a scheduler and two worker processes on 127.0.0.1, one of them killed mid-way
(every grid point in the table exactly once), and a sweep killed and resumed (its table equal to an
uninterrupted sweep's)."""
import json
import os
import signal
import socket
import subprocess
import sys
import threading
import time

import pandas as pd
import pytest

import hybridcont as hc
from hybridcont import sweeps

GRID = {"k": (20, 80, 4), "w2": (3, 7, 4)}  # 16 grid points of the SLIP
OPTIONS = {"until": {"H": 1.7}}


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start(args):
    return subprocess.Popen([sys.executable, "-m", *args], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            env=dict(os.environ), start_new_session=True)


def wait_for_workers(address, n, timeout=60):
    from dask.distributed import Client
    with Client(address, timeout=timeout) as client:
        client.wait_for_workers(n, timeout=timeout)


def complete_points(out):
    folder = os.path.join(out, "points")
    return [p for p in os.listdir(folder) if not p.startswith(".")] if os.path.isdir(folder) else []


def test_a_killed_worker_costs_no_grid_point(tmp_path):
    port = free_port()
    address = "tcp://127.0.0.1:%d" % port
    scheduler = start(["distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", str(port),
                       "--dashboard-address", ":0"])
    workers = [start(["distributed.cli.dask_worker", address, "--nthreads", "1", "--no-nanny",
                      "--host", "127.0.0.1", "--dashboard-address", ":0"]) for _ in range(2)]
    try:
        wait_for_workers(address, 2)
        out = str(tmp_path / "map")
        result = {}
        runner = threading.Thread(target=lambda: result.update(table=hc.sweep(
            "slip", GRID, out, scheduler=address, progress=False, **OPTIONS)))
        runner.start()
        deadline = time.time() + 120
        while len(complete_points(out)) < 3 and time.time() < deadline:
            time.sleep(0.05)
        assert len(complete_points(out)) < 16, "the sweep ended before a worker could be killed"
        os.killpg(workers[0].pid, signal.SIGKILL)  # mid-way: its running task is lost with it
        runner.join(timeout=300)
        assert not runner.is_alive()
        table = result["table"]
        points = table.drop_duplicates(["point", "family"])
        assert len(points) == len(table)  # no grid point twice
        assert sorted(table["point"].unique()) == sorted(pid for pid, _ in sweeps.grid_points(sweeps.grid_values(GRID)))
        assert sorted(complete_points(out)) == sorted(table["point"].unique())
        assert not [p for p in os.listdir(os.path.join(out, "points")) if p.startswith(".partial")]
        # The grid's parameters by name; hopping in place exists at every point, stable over a range of H.
        hopping = table[table.family == "hopping in place"]
        assert len(hopping) == 16 and hopping.exists.all() and hopping.stable.all()
        assert set(hopping["k"]) == {20.0, 40.0, 60.0, 80.0}
        # The same numbers a study at that grid point gives alone.
        row = hopping[(hopping.k == 40.0) & (hopping.w2 == 3 + 4 / 3)].iloc[0]
        alone = hc.run("slip", set={"k": 40.0, "w2": 3 + 4 / 3}, progress=False, **OPTIONS)
        stable = alone.families.query("family == 'hopping in place' and kind == 'stable'")
        assert row.stable_from == pytest.approx(stable["from"].min(), abs=1e-12)
    finally:
        for p in workers + [scheduler]:
            try:
                os.killpg(p.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            p.wait()


def test_an_interrupted_sweep_resumes_to_the_table_of_an_uninterrupted_one(tmp_path):
    whole = hc.sweep("slip", GRID, str(tmp_path / "whole"), workers=2, progress=False, **OPTIONS)
    out = str(tmp_path / "cut")
    command = [sys.executable, "-m", "hybridcont.sweeps", "slip", "--grid", "k=20:80:4", "--grid", "w2=3:7:4",
               "--until", "H=1.7", "--workers", "1", "--quiet", "--out", out]
    proc = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=dict(os.environ),
                            start_new_session=True)
    deadline = time.time() + 120
    while len(complete_points(out)) < 4 and time.time() < deadline and proc.poll() is None:
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)  # the sweep, its cluster and its workers
    proc.wait()
    done = len(complete_points(out))
    assert 0 < done < 16
    proc = subprocess.run(command + ["--resume"], capture_output=True, text=True, env=dict(os.environ))
    assert proc.returncode == 0, proc.stderr
    resumed = pd.read_csv(os.path.join(out, "table.csv"))
    expected = pd.read_csv(str(tmp_path / "whole" / "table.csv"))
    pd.testing.assert_frame_equal(resumed, expected)
    assert len(whole) == len(expected)
    # A resume with another grid is refused, naming the folder.
    proc = subprocess.run(command[:-2] + ["--out", out, "--resume", "--grid", "m=1:2:2"], capture_output=True,
                          text=True, env=dict(os.environ))
    assert proc.returncode == 2 and "another definition" in proc.stderr


def test_the_tool_runs_a_sweep_and_refuses_a_bad_grid(tmp_path):
    tool = os.environ.get("HYBRIDCONT_BIN", "build/hybridcont")
    out = str(tmp_path / "tool")
    proc = subprocess.run([tool, "sweep", "slip", "--grid", "k=20:40:2", "--grid", "w2=4:5:2", "--max-branches", "3",
                           "--workers", "1", "--quiet", "--out", out], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert "4 grid points" in proc.stdout and os.path.exists(os.path.join(out, "map-hopping-in-place.png"))
    table = pd.read_csv(os.path.join(out, "table.csv"))
    assert list(table.columns[:4]) == ["k", "w2", "point", "family"] and table["point"].nunique() == 4
    proc = subprocess.run([tool, "sweep", "slip", "--grid", "kk=1:2:2", "--out", str(tmp_path / "bad")],
                          capture_output=True, text=True)
    assert proc.returncode == 2 and "grid kk: model 'slip' has no parameter 'kk'" in proc.stderr
    assert not os.path.exists(tmp_path / "bad")  # nothing written
    proc = subprocess.run([tool, "sweep", "slip", "--grid", "k=1:2"], capture_output=True, text=True)
    assert proc.returncode == 2 and "NAME=START:STOP:COUNT" in proc.stderr


def test_neighbours_orbits_start_a_grid_point_the_models_own_start_cannot(tmp_path):
    """The bipedal model's walking guess, written for k = 25.5 and beta = 0.367, does not converge at k = 17.857,
    beta = 0.30; the sweep covers the grid from the point nearest the model's own parameters outwards and
    starts each point from the orbits its neighbour found: every point walks."""
    with pytest.raises(ValueError, match="does not converge"):
        hc.run("bipedal-slip", set={"k": 17.857, "beta": 0.30}, progress=False, max_branches=6)
    table = hc.sweep("bipedal-slip", {"beta": (0.30, 0.3665, 4)}, str(tmp_path / "walk"), progress=False,
                     max_branches=6, set={"k": 17.857}, maps=False)
    walking = table[table.family == "walking"].sort_values("beta")
    assert list(walking.exists) == [True] * 4
    assert list(walking.strategy) == ["neighbour 1", "neighbour 2", "neighbour 3", "explore"]
    assert walking.iloc[0].stable  # walking at beta = 0.30 has a stable stretch


def test_the_sweep_report_opens_offline_and_a_click_shows_a_grid_point(tmp_path):
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir))
    from browser import CHROMIUM, Browser, wait_for
    if CHROMIUM is None:
        pytest.skip("no chromium (sh scripts/install-deps.sh installs it)")
    out = tmp_path / "small"
    hc.sweep("slip", {"k": (20, 60, 3), "w2": (3, 6, 3)}, str(out), workers=1, progress=False, max_branches=3,
             maps=False)
    page = out / "sweep-report.html"
    text = page.read_text()
    assert "<script src" not in text and "http" not in text.split("/*")[0][:2000]
    browser = Browser(page.as_uri())
    try:
        wait_for(browser, "document.readyState === 'complete' && !!document.querySelector('#map .scatterlayer')")
        assert browser.errors() == []
        legend = browser.evaluate("[...document.querySelectorAll('#map .legendtext')].map(t => t.textContent)")
        assert "stable" in legend, legend
        # A real mouse click on the first grid point's square selects its row of the table.
        where = browser.evaluate("""(() => {
            const gd = document.getElementById('map'), pt = gd._fullData[0];
            const xa = gd._fullLayout.xaxis, ya = gd._fullLayout.yaxis, box = gd.getBoundingClientRect();
            return [box.left + xa._offset + xa.l2p(pt.x[0]), box.top + ya._offset + ya.l2p(pt.y[0])];
        })()""")
        browser.click(*where)
        wait_for(browser, "document.getElementById('point').innerText.includes('grid point')")
        shown = browser.evaluate("document.getElementById('point').innerText")
        assert "hopping in place" in shown and "strategy" in shown, shown
        browser.evaluate("document.getElementById('colour').value = 'stable_from';"
                         "document.getElementById('colour').dispatchEvent(new Event('change'))")
        wait_for(browser, "!!document.querySelector('#map .colorbar')")
        assert browser.errors() == []
    finally:
        browser.close()


def test_a_model_written_in_python_is_swept_with_its_parameters(tmp_path):
    """A Model built with SymPy travels to the workers as its model text (the library's model does not travel
    between processes), with the parameters set on it."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from package_test import bouncing_ball_in_python
    ball = bouncing_ball_in_python().build().with_parameters(m=2.0)
    table = hc.sweep(ball, {"g": [1.0, 4.0]}, str(tmp_path / "ball"), workers=1, progress=False, maps=False)
    assert list(table.point) == ["0", "1"] and table.exists.all()
    # H = m g y + m dy^2 / 2: at m = 2 the family's physical range ends where H's bound does, whatever g is
    assert (table.physical_to == 1.0).all()
    with open(os.path.join(str(tmp_path / "ball"), "sweep.json")) as f:
        assert json.load(f)["options"]["set"] == {"g": 1.0, "m": 2.0}
