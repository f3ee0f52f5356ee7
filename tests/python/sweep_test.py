"""Sweeps on a real Dask cluster: a scheduler and two worker processes on 127.0.0.1, one of them killed mid-way
(every grid point in the table exactly once), and a sweep killed and resumed (its table equal to an
uninterrupted sweep's)."""
import json
import os
import re
import signal
import socket
import subprocess
import sys
import threading
import time

import numpy as np
import pandas as pd
import pytest

import hybridcont as hc
from hybridcont import sweeps

GRID = {"k": (20, 80, 3), "w2": (3, 7, 2)}  # 6 grid points of the SLIP
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
        while len(complete_points(out)) < 2 and time.time() < deadline:
            time.sleep(0.05)
        assert len(complete_points(out)) < 6, "the sweep ended before a worker could be killed"
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
        assert len(hopping) == 6 and hopping.exists.all() and hopping.stable.all()
        assert set(hopping["k"]) == {20.0, 50.0, 80.0} and set(hopping["w2"]) == {3.0, 7.0}
        # The same numbers a study at that grid point gives alone.
        row = hopping[(hopping.k == 50.0) & (hopping.w2 == 7.0)].iloc[0]
        alone = hc.run("slip", set={"k": 50.0, "w2": 7.0}, progress=False, **OPTIONS)
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
    command = [sys.executable, "-m", "hybridcont.sweeps", "slip", "--grid", "k=20:80:3", "--grid", "w2=3:7:2",
               "--until", "H=1.7", "--workers", "1", "--quiet", "--out", out]
    proc = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=dict(os.environ),
                            start_new_session=True)
    deadline = time.time() + 120
    while len(complete_points(out)) < 2 and time.time() < deadline and proc.poll() is None:
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)  # the sweep, its cluster and its workers
    proc.wait()
    done = len(complete_points(out))
    assert 0 < done < 6
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
    proc = subprocess.run([tool, "sweep", "slip", "--grid", "k=-10:20:2", "--out", str(tmp_path / "range")],
                          capture_output=True, text=True)
    assert proc.returncode == 2 and "grid k: the value -10:" in proc.stderr and "range" in proc.stderr, proc.stderr
    assert not os.path.exists(tmp_path / "range")
    proc = subprocess.run([tool, "sweep", "slip", "--grid", "k=1:2"], capture_output=True, text=True)
    assert proc.returncode == 2 and "NAME=START:STOP:COUNT" in proc.stderr
    # Options are checked by the library as `run` checks them: no nan, inf or empty name; several monitor values.
    for bad, said in ((["--set", "k=nan"], "not finite"), (["--until", "=1"], "expected NAME=VALUE"),
                      (["--bound", "H=inf:2"], "not finite"), (["--fix", "H=1e999"], "not finite")):
        proc = subprocess.run([tool, "sweep", "slip", "--grid", "k=20:40:2", *bad, "--out", str(tmp_path / "nan")],
                              capture_output=True, text=True)
        assert proc.returncode == 2 and said in proc.stderr, (bad, proc.stderr)
        assert not os.path.exists(tmp_path / "nan")
    # Requests that cannot finish, refused before anything runs: a grid of a hundred million studies, a grid
    # parameter given twice, no worker process.
    for bad, said in ((["--grid", "k=1:2:100000000"], "grid: 100,000,000 grid points (k: 100000000), each a whole "
                                                      "study: more than 10000"),
                      (["--grid", "k=20:40:2", "--grid", "k=1:2:2"], "--grid k: given twice"),
                      (["--grid", "k=20:40:2", "--workers", "-1"], "argument --workers: '-1': at least 1"),
                      (["--grid", "k=20:40:2", "--workers", "0"], "argument --workers: '0': at least 1")):
        proc = subprocess.run([tool, "sweep", "slip", *bad, "--out", str(tmp_path / "big")], capture_output=True,
                              text=True, timeout=60)
        assert proc.returncode == 2 and said in proc.stderr, (bad, proc.stderr)
        assert not os.path.exists(tmp_path / "big")
    with pytest.raises(ValueError, match="more than 3; a mistyped count"):
        hc.sweep("slip", {"k": (20, 40, 2), "w2": (4, 5, 2)}, str(tmp_path / "big"), max_grid_points=3)
    with pytest.raises(ValueError, match="workers 0: a whole number of processes, at least 1"):
        hc.sweep("slip", {"k": (20, 40, 2)}, str(tmp_path / "big"), workers=0)
    # Families in a free parameter at each grid point: explored whole (a guide continues families in H), said.
    out = str(tmp_path / "free")
    proc = subprocess.run([tool, "sweep", "slip", "--grid", "w2=5:6:2", "--free", "k", "--fix", "H=1.5", "--workers",
                           "1", "--quiet", "--no-maps", "--strategy", "continue", "--out", out], capture_output=True,
                          text=True)
    assert proc.returncode == 0 and "note: sweep: strategy 'continue' needs families in H" in proc.stderr, proc.stderr
    table = pd.read_csv(os.path.join(out, "table.csv"))
    assert set(table.strategy) == {"explore"} and table[table.family == "hopping in place"].physical.all()
    # The range of a family in k at H = 1.5 is in k (the bound of k is the model's, 10 to 160).
    assert table[table.family == "hopping in place"].physical_to.max() == pytest.approx(160)


def test_neighbours_orbits_start_a_grid_point_the_models_own_start_cannot(tmp_path):
    """The bipedal model's walking guess, written for k = 25.5 and beta = 0.367, does not converge at k = 17.857,
    beta = 0.30: a study there carries it from the model's own values; the sweep covers the grid from the point
    nearest the model's own parameters outwards and starts each point from the orbits its neighbour found: every
    point walks. The file's word alone (one_word): the neighbours' orbits are walking's, and the other words'
    families, most of a study's time on this model, are followed in the studies of tests/study_test.cc."""
    alone = hc.run("bipedal-slip", set={"k": 17.857, "beta": 0.30}, progress=False, max_branches=6,
                   one_word=True)
    assert "start carried from the model's own k = 25.4842, beta = 0.366519 to 17.857, 0.3" in str(alone)
    assert "walking" in set(alone.families.family)
    table = hc.sweep("bipedal-slip", {"beta": (0.30, 0.3665, 4)}, str(tmp_path / "walk"), progress=False,
                     max_branches=6, one_word=True, set={"k": 17.857}, maps=False)
    walking = table[table.family == "walking"].sort_values("beta")
    assert list(walking.exists) == [True] * 4
    assert list(walking.strategy) == ["explore from %d's orbits" % i for i in (1, 2, 3)] + ["explore"]
    # Continuing: a study stopped at max_branches guides no other, so each point is explored whole, and says why.
    table = hc.sweep("bipedal-slip", {"beta": (0.30, 0.3665, 4)}, str(tmp_path / "walk2"), progress=False,
                     max_branches=6, one_word=True, set={"k": 17.857}, maps=False, strategy="continue")
    walking = table[table.family == "walking"].sort_values("beta")
    assert list(walking.strategy) == ["explore from %d's orbits (%d did not complete)" % (i, i) for i in (1, 2, 3)] + \
        ["explore"]
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


def test_continuing_the_neighbours_families_gives_the_whole_explorations_table(tmp_path):
    """Strategy "continue" (each grid point traces only the half-branches that led to its neighbour's families)
    against "explore" (every grid point explored whole) over the SLIP's (k, w2) from 10 to 160 and 2 to 10: the
    same rows, range for range and special point for special point (their ids are each study's own)."""
    grid = {"k": (10, 160, 3), "w2": (2, 10, 3)}
    tables = {s: hc.sweep("slip", grid, str(tmp_path / s), workers=2, progress=False, maps=False, strategy=s)
              for s in ("continue", "explore")}
    kinds = tables["continue"].strategy.str.split(" ").str[0].value_counts().to_dict()
    assert kinds == {"continue": len(tables["continue"]) - 3, "explore": 3}  # the first point's 3 families
    columns = ["point", "family", "exists", "physical", "stable", "physical_from", "physical_to", "stable_from",
               "stable_to", "status"]

    def same_form(t):
        t = t.assign(special_points=t.special_points.fillna("").map(
            lambda s: ";".join(sorted(re.sub(r"^([A-Z]+)\d+", r"\1", p) for p in s.split(";")))))
        return t[columns + ["special_points"]].sort_values(["point", "family"]).reset_index(drop=True)
    pd.testing.assert_frame_equal(same_form(tables["continue"]), same_form(tables["explore"]), check_exact=True)
    # Each grid point's saved study says what the guide left out, and which neighbour guided it.
    row = tables["continue"][tables["continue"].strategy.str.startswith("continue")].iloc[0]
    with open(os.path.join(str(tmp_path / "continue"), "points", row.point, "summary.json")) as f:
        guided = json.load(f)["guided"]
    assert guided["pruned_half_branches"] >= 3
    assert "continue from " + os.path.basename(guided["from"]) == row.strategy


def test_curves_over_a_line_of_the_grid_pass_through_its_grid_points_ranges(tmp_path):
    """A sweep with curves="k": the grid point nearest the model's own k continues its families' special points
    in (H, k) over the grid's range of k; the period-doubling curve of hopping in place (its PD4, where its
    stable range begins) passes through the stable range's beginning that each grid point's own study
    located, and the report draws the plane."""
    out = str(tmp_path / "line")
    table = hc.sweep("slip", {"k": (20, 80, 5)}, out, workers=2, progress=False, maps=False, curves="k",
                     until={"H": 2}, strategy="continue")
    lines = sweeps.curve_lines(out)
    assert list(lines) == ["*"] and lines["*"]["point"] == "1"  # k = 35, nearest the model's k = 40
    pd_curves = [c for c in lines["*"]["curves"] if c["type"] == "period-doubling" and c["family"] == "hopping in place"]
    assert len(pd_curves) == 1
    curve = pd_curves[0]
    assert min(curve["p"]) == pytest.approx(20) and max(curve["p"]) == pytest.approx(80)
    p, H = np.array(curve["p"]), np.array(curve["H"])
    order = np.argsort(p)
    p, H = p[order], H[order]
    assert np.all(np.diff(p) > 0)  # one H per k: no fold in k
    slope = np.diff(H) / np.diff(p)
    hopping = table[table.family == "hopping in place"].sort_values("k")
    assert len(hopping) == 5 and hopping.stable.all()
    for r in hopping.itertuples():
        # Between the curve's two samples around the grid's k the curve is the chord, to within its bending
        # over that step (the change of the chords' slopes next to it, times the step).
        i = int(np.clip(np.searchsorted(p, r.k) - 1, 0, len(p) - 2))
        h = p[i + 1] - p[i]
        bend = max(abs(slope[j + 1] - slope[j]) for j in range(max(0, i - 1), min(len(slope) - 1, i + 1)))
        at = H[i] + slope[i] * (r.k - p[i])
        assert abs(at - r.stable_from) <= bend * h + 1e-8, (r.k, at, r.stable_from, bend * h)
    # The report draws the plane along the line: the family's ranges and the curves.
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir))
    from browser import CHROMIUM, Browser, wait_for
    if CHROMIUM is None:
        pytest.skip("no chromium (sh scripts/install-deps.sh installs it)")
    browser = Browser((tmp_path / "line" / "sweep-report.html").as_uri())
    try:
        wait_for(browser, "document.readyState === 'complete' && !!document.querySelector('#plane .scatterlayer')")
        assert browser.errors() == []
        names = browser.evaluate("document.getElementById('plane').data.map(t => t.name)")
        assert "hopping in place: stable range" in names and "period-doubling curve of PD4 (hopping in place)" in names, names
        assert "curves continued from grid point 1" in browser.evaluate("document.getElementById('plane-title').textContent")
    finally:
        browser.close()


def test_a_script_that_sweeps_at_its_top_level_or_from_standard_input_runs(tmp_path):
    """A local cluster's workers are started without the user's script (multiprocessing's spawn would run it
    again in each worker: a sweep at the top level then never started, one read from standard input failed)."""
    out = tmp_path / "top"
    script = tmp_path / "top_level.py"
    script.write_text("import hybridcont as hc\n"
                      "t = hc.sweep('slip', {'k': (30, 50, 3)}, %r, workers=2, progress=False, maps=False, "
                      "overwrite=True, until={'H': 1.6})\n"
                      "print('rows', len(t))\n" % str(out))
    for how in ("file", "stdin"):
        args = [sys.executable, str(script)] if how == "file" else [sys.executable, "-"]
        proc = subprocess.run(args, input=None if how == "file" else script.read_text(), capture_output=True,
                              text=True, timeout=300, env=dict(os.environ))
        assert proc.returncode == 0 and "rows 9" in proc.stdout, (how, proc.stdout, proc.stderr[-2000:])


def test_damaged_sweep_files_are_named_and_a_resume_refuses_them(tmp_path):
    """A sweep's folder is untrusted input: a damaged definition or grid point's rows is refused on resume
    (exit 2, naming the file and how to recompute the point), nothing computed or rewritten."""
    tool = os.environ.get("HYBRIDCONT_BIN", "build/hybridcont")
    out = tmp_path / "damaged"
    args = [tool, "sweep", "slip", "--grid", "k=30:40:2", "--until", "H=1.5", "--workers", "1", "--quiet",
            "--no-maps", "--out", str(out)]
    assert subprocess.run(args, capture_output=True, text=True).returncode == 0
    rows = out / "points" / "1" / "rows.json"
    good = rows.read_text()
    for damage, expected in (("[{\"point\": \"1\"}]", "row 0 lacks 'family'"), ("{", "not a grid point's rows"),
                             ("[]", "a non-empty list expected")):
        rows.write_text(damage)
        table = (out / "table.csv").read_text()
        proc = subprocess.run(args + ["--resume"], capture_output=True, text=True)
        assert proc.returncode == 2 and str(rows) in proc.stderr and expected in proc.stderr, proc.stderr
        assert "remove %s to compute the grid point again" % (out / "points" / "1") in proc.stderr
        assert (out / "table.csv").read_text() == table  # nothing rewritten
    rows.write_text(good)
    (out / "sweep.json").write_text("{\"grid\": 3}")
    proc = subprocess.run(args + ["--resume"], capture_output=True, text=True)
    assert proc.returncode == 2 and "sweep.json" in proc.stderr, proc.stderr
    assert subprocess.run(args + ["--overwrite"], capture_output=True, text=True).returncode == 0  # replaced whole


def test_overwrite_replaces_what_a_sweep_wrote_and_keeps_the_users_files(tmp_path):
    from hybridcont.sweeps import run as sweep_run
    out = tmp_path / "sweep"
    (out / "points" / "0_0").mkdir(parents=True)
    for name in ("sweep.json", "table.csv", "sweep-report.html", "map-hopping.png", "plane-a.svg"):
        (out / name).write_text("{}")
    (out / "points" / "0_0" / "rows.json").write_text("[]")
    (out / "notes.txt").write_text("the user's own notes")
    (out / "mine").mkdir()
    (out / "mine" / "data.csv").write_text("1,2\n")
    definition = {"format": 1, "model": "slip", "grid": {"k": [20.0]}, "options": {}}
    sweep_run._prepare_folder(str(out), definition, "explore", [("0", {"k": 20.0})], None, resume=False,
                              overwrite=True)
    assert sorted(os.listdir(out)) == ["mine", "notes.txt", "points", "sweep.json"]
    assert os.listdir(out / "points") == [] and (out / "notes.txt").read_text() == "the user's own notes"
    assert (out / "mine" / "data.csv").exists() and json.loads((out / "sweep.json").read_text()) == definition



def _children(pid):
    """The live processes whose parent is `pid` (zombies count as gone)."""
    out = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open("/proc/%s/stat" % entry) as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid and fields[0] != "Z":
            out.append(int(entry))
    return out


def _alive(pid):
    try:
        with open("/proc/%d/stat" % pid) as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


def test_killing_the_sweep_command_takes_its_python_process_down(tmp_path):
    tool = os.environ.get("HYBRIDCONT_BIN", "build/hybridcont")
    proc = subprocess.Popen([tool, "sweep", "slip", "--grid", "k=20:40:8", "--workers", "1", "--quiet", "--no-maps",
                             "--out", str(tmp_path / "killed")], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 60
    while time.time() < deadline and not _children(proc.pid):
        time.sleep(0.2)
    python = _children(proc.pid)
    assert python, "the sweep command started no Python process"
    time.sleep(2)  # the sweep under way
    proc.kill()
    proc.wait()
    deadline = time.time() + 60
    while time.time() < deadline and any(_alive(p) for p in python):
        time.sleep(0.2)
    assert not any(_alive(p) for p in python), "the Python process outlived the killed command"


def test_a_hostile_family_name_cannot_break_the_sweep_report(tmp_path):
    from hybridcont.sweeps import report
    if not os.path.exists(os.path.join(hc._paths.REPORT, "plotly-basic.min.js")):
        pytest.skip("built without npm: no report")
    name = "/*HYBRIDCONT_VIEWER*/<!--<script></script>"
    (tmp_path / "sweep.json").write_text(json.dumps({"format": 1, "model": "slip", "grid": {"k": [20.0]},
                                                     "strategy": "explore", "options": {}}))
    pd.DataFrame([{"k": 20.0, "point": "0", "family": name, "status": "completed", "strategy": "explore",
                   "exists": True, "physical": True, "stable": False, "physical_from": 1.0, "physical_to": 2.0,
                   "stable_from": "", "stable_to": "", "physical_ranges": "1..2", "stable_ranges": "",
                   "special_points": "[]"}]).to_csv(tmp_path / "table.csv", index=False)
    page = open(report.write_report(str(tmp_path)), encoding="utf-8").read()
    with open(os.path.join(hc._paths.REPORT, "sweep.js"), encoding="utf-8") as f:
        viewer = f.read()
    assert page.count(viewer.strip()[:200]) == 1  # the viewer inserted once, where the template says
    assert name not in page
    assert json.dumps(name).replace("<", "\\u003c") in page
    assert not os.path.exists(tmp_path / "sweep-report.html.tmp")
