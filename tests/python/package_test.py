"""The Python package against the command line and against models written twice.

Environment: PYTHONPATH holds the built package (build/python), HYBRIDCONT_BIN the built tool.
"""
import json
import os
import re
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest
import sympy as sp

import hybridcont as hc

TOOL = os.environ.get("HYBRIDCONT_BIN", "build/hybridcont")
ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, os.pardir)
MODELS = os.path.join(ROOT, "models")


def cli(*args):
    proc = subprocess.run([TOOL, *args], capture_output=True, text=True, timeout=600)
    return proc.returncode, proc.stdout, proc.stderr


def special_points(summary):
    return [(sp["type"], sp["branch"], sp["index"], sp["H"], sp["T"], sp["status"])
            for sp in summary["special_points"]]


@pytest.mark.parametrize("name", ["bouncing-ball", "rocking-block", "bouncing-rod", "slip"])
def test_same_diagram_as_the_command_line_on_the_paper_models(tmp_path, name):
    rc, _, err = cli("run", name, "--out", str(tmp_path / "cli"), "--quiet")
    assert rc == 0, err
    with open(tmp_path / "cli" / "summary.json") as f:
        expected = json.load(f)
    study = hc.run(name, out=tmp_path / "py", progress=False, threads=1)
    assert study.status == "completed"
    got = special_points(study.summary)
    want = special_points(expected)
    assert len(got) == len(want)
    for g, w in zip(got, want):
        assert g[:3] == w[:3] and g[5] == w[5], (g, w)
        assert g[3] == pytest.approx(w[3], rel=1e-12, abs=1e-12) and g[4] == pytest.approx(w[4], rel=1e-12, abs=1e-12)
    # The points table is the typed study's: every column of every branch file, one row per point, each number
    # as the file holds it (to the bit).
    points = study.points
    with open(tmp_path / "py" / "branch-0.csv") as f:
        header = f.readline().strip().split(",")
    assert list(points.columns[:5]) == ["branch", "family", "index", "H", "T"]
    assert set(points.columns) == {"branch", "family"} | set(header)
    assert len(points) == sum(b["points"] for b in study.summary["branches"])
    import pandas as pd
    saved = pd.read_csv(tmp_path / "py" / "branch-0.csv", float_precision="round_trip")
    mine = points[points.branch == 0].reset_index(drop=True)
    for column in header:
        a, b = mine[column], saved[column]
        if a.dtype == object or b.dtype == object:
            assert list(a.fillna("")) == list(b.fillna("")), column
        else:
            assert ((a == b) | (a.isna() & b.isna())).all(), column
    assert os.path.exists(tmp_path / "py" / "report.html")


def test_dataframes_name_what_they_hold():
    study = hc.run("slip", progress=False, max_branches=8)
    assert {"label", "type", "branch", "index", "H", "T", "status", "precision", "u"} <= set(study.special_points.columns)
    assert {"family", "kind", "continued", "from", "to", "from_end", "to_end", "branches"} <= set(study.families.columns)
    assert {"id", "family", "parent", "termination", "points", "word"} <= set(study.branches.columns)
    hopping = study.families.query("family == 'hopping in place' and kind == 'stable'")
    assert hopping["from"].iloc[0] == pytest.approx(1.282809324, abs=1e-9)
    orbit = study.orbits[0]
    assert {"t", "segment", "phase", "stance.alpha", "draw.body.x"} <= set(orbit.columns)
    assert orbit.attrs["monodromy"].shape == (4, 4)
    u = study.u(2, 10)
    assert len(u) == len(study.unknowns)
    e = study.evaluate(2, 10)
    assert e["ok"] and np.abs(e["r"]).max() < 1e-9 and e["dr"].shape == (len(u) - 1, len(u))


def test_bad_input_is_a_value_error_with_the_command_lines_message(tmp_path):
    rc, _, err = cli("run", "slip", "--set", "k=-1", "--out", str(tmp_path / "cli"))
    assert rc == 2
    with pytest.raises(ValueError) as e:
        hc.run("slip", set={"k": -1}, progress=False)
    detail = str(e.value).split(": ", 1)[1]  # the message after the field's name (--set / parameters[0])
    assert detail in err, (str(e.value), err)
    with pytest.raises(ValueError, match="unknown model 'nosuch'"):
        hc.run("nosuch", progress=False)
    with pytest.raises(ValueError, match=r"bound \{'H': 2\}: expected \{name: \(lower, upper\)\}"):
        hc.run("slip", bound={"H": 2}, progress=False)
    with pytest.raises(ValueError, match=r"<text>:4: phases\[0\].name: expected a string"):  # line and field
        hc.model(text="hybridcont = 1\nname = 'x'\n[[phases]]\nname = 3\n")
    with pytest.raises(ValueError, match="model-file language has no"):
        hc.ModelBuilder("x").family("f", when=sp.gamma(sp.Symbol("a")))
    with pytest.raises(ValueError, match="a string where an expression belongs"):
        hc.ModelBuilder("x").definition("l", "a + b")


def test_the_options_are_the_librarys_declaration_in_pythons_words(capsys):
    import argparse
    from hybridcont import _hybridcont as native
    from hybridcont.sweeps import cli as sweep_cli
    specs = native.study_options()
    for spec in specs:  # run's docstring is the declaration
        if spec["keyword"] not in ("model", "out"):
            assert "\n    ``%s``" % spec["keyword"] in hc.run.__doc__, spec["keyword"]
    with pytest.raises(TypeError, match="unexpected keyword argument 'untill'"):
        hc.run("slip", untill={"H": 1}, progress=False)
    with pytest.raises(ValueError, match=r"^fix 'H=1.5': needs free PARAMETER"):
        hc.run("slip", fix={"H": 1.5}, progress=False)
    with pytest.raises(ValueError, match=r"^set \{'k': nan\}: expected finite numbers"):
        hc.run("slip", set={"k": float("nan")}, progress=False)
    with pytest.raises(ValueError, match=r"^threads 2.5: expected a whole number"):
        hc.run("slip", threads=2.5, progress=False)
    from hybridcont.study import check
    notes = check("slip", until={"H": 2.5})
    assert notes == ["until H=2.5 lies outside the bound [0, 2] of H: the bound is widened to [0, 2.5] (give "
                     "bound H=LOWER:UPPER to keep it)"], notes
    # The sweep's command line: the declared options a sweep applies at every grid point, checked by the library
    # as `run` checks them (several values of --monitor, a value that is not finite refused).
    parser = argparse.ArgumentParser()
    sweep_cli._add_study_options(parser)
    args = parser.parse_args(["--monitor", "apex=1,2", "--set", "k=30", "--bound", "H=0:", "--no-symmetry"])
    assert sweep_cli._study_keywords(args, parser) == {
        "monitor": {"apex": [1.0, 2.0]}, "set": {"k": 30.0}, "bound": {"H": (0.0, None)}, "no_symmetry": True}
    for bad, said in ((["--set", "k=nan"], "--set 'k=nan': value 'nan' is not finite"),
                      (["--set", "=1"], "--set '=1': expected NAME=VALUE"),
                      (["--set", "k=1", "--set", "k=2"], "--set 'k=2': 'k' is given twice")):
        with pytest.raises(SystemExit) as e:
            sweep_cli._study_keywords(parser.parse_args(bad), parser)
        assert e.value.code == 2
        assert said in capsys.readouterr().err


def test_a_model_file_from_python():
    walker = hc.model(os.path.join(MODELS, "compass-gait.toml"), set={"gamma": 0.05})
    assert walker.parameters["gamma"] == 0.05 and not walker.conservative
    study = hc.run(walker, progress=False)
    assert set(study.branches.family) == {"long-step gait", "short-step gait"}


def bouncing_ball_in_python():
    """models/bouncing-ball.toml, written with SymPy as a phase given by its vector field."""
    b = hc.ModelBuilder("bouncing-ball-sympy", title="bouncing ball")
    g = b.parameter("g", 1.0, range="(0, inf)")
    m = b.parameter("m", 1.0, range="(0, inf)")
    y, dy = sp.symbols("y dy")
    b.phase("flight", states=[y, dy], typical=[0.5, 0.3], ode={y: dy, dy: -g}, energy=m * g * y + m * dy ** 2 / 2,
            event=y, reset={y: y, dy: -dy}, anchor=dy)
    b.symmetry("time-reversal", {"flight": [dy]}, reverses_time=True)
    b.start("singular")
    b.run(bounds={"xi": [-1, 1], "H": [-1, 1]}, keyframes={"component": "H", "value": 0.5})
    return b


def test_a_sympy_model_equals_its_model_file_twin():
    twin = hc.model(os.path.join(MODELS, "bouncing-ball.toml"))
    ball = bouncing_ball_in_python().build()
    file_study = hc.run(twin, progress=False)
    for branch, index in ((0, 5), (0, 15), (1, 10)):
        u = file_study.u(branch, index)
        ours, theirs = ball.evaluate(u), twin.evaluate(u)
        assert np.abs(ours["r"] - theirs["r"]).max() <= 1e-12
        assert np.abs(ours["dr"] - theirs["dr"]).max() <= 1e-12 * max(1.0, np.abs(theirs["dr"]).max())
    study = hc.run(ball, progress=False)
    a, b = study.special_points, file_study.special_points
    assert list(a.type) == list(b.type)
    assert np.allclose(a.H, b.H, atol=1e-9) and np.allclose(a["T"], b["T"], atol=1e-9)


def test_model_builder_declares_observables_and_constraints():
    """As a model file's [observables] and [constraints]: the ball's apex (its largest height in flight) is
    H / (m g) exactly, so the monitored crossing apex = 0.5 is located at H = 0.5."""
    b = bouncing_ball_in_python()
    y = sp.Symbol("y")
    assert b.observable("apex", maximum={"flight": y}, description="highest point in flight") == "apex"
    b.constraint("above_floor", phases={"flight": y + 1}, description="never below the floor")
    with pytest.raises(ValueError, match="give exactly one of"):
        b.observable("both", value="x1_dy", mean={"flight": y})
    with pytest.raises(ValueError, match="give phases"):
        b.constraint("none")
    study = hc.run(b.build(), progress=False, monitor={"apex": [0.5]})
    uz = study.special_points[(study.special_points.type == "UZ") & (study.special_points.status == "located")]
    assert len(uz) >= 1 and np.allclose(uz.H, 0.5, atol=1e-9), uz[["label", "H"]]
    assert "above_floor" in study.points.columns and (study.points[study.points.physical == 1]["above_floor"] > 0).all()


def test_progress_reaches_python_and_the_gil_is_released_while_computing():
    calls = []
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    counter = threading.Thread(target=count)
    counter.start()
    try:
        hc.run("bipedal-slip", max_branches=6, threads=1,
               progress=lambda stage, branches, points, message: calls.append((stage, points)))
    finally:
        stop.set()
        counter.join()
    assert calls and calls[-1][1] >= max(p for _, p in calls) > 100
    # The counting thread ran throughout (it would stall for the whole study if the GIL were held).
    assert len(ticks) > 100 and max(np.diff(ticks)) < 0.5


def test_ctrl_c_ends_the_study_and_keeps_the_work(tmp_path):
    script = ("import hybridcont as hc, warnings\n"
              "warnings.simplefilter('always')\n"
              "s = hc.run('bipedal-slip', out=%r, progress=False, threads=1)\n"
              "print('status', s.status, 'branches', len(s.branches), 'interrupted', s.interrupted)\n"
              % str(tmp_path / "run"))
    proc = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env=dict(os.environ))
    time.sleep(2.0)  # imported, the study under way (it takes ~5 s)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, err
    assert "status cancelled" in out and "interrupted True" in out, out
    assert "the study was interrupted: the work so far is kept" in err
    branches = int(out.split("branches ")[1].split()[0])
    assert branches > 0
    with open(tmp_path / "run" / "summary.json") as f:
        assert json.load(f)["status"] != "complete"


def test_restart_save_load_and_the_report(tmp_path):
    study = hc.run("slip", progress=False, max_branches=6)
    doubled = study.continue_from("PD4", progress=False)
    rc, _, err = cli("run", "slip", "--from", study.path, "--at", "PD4", "--out", str(tmp_path / "cli"), "--quiet")
    assert rc == 0, err
    with open(tmp_path / "cli" / "summary.json") as f:
        assert special_points(doubled.summary) == special_points(json.load(f))
    saved = study.save(tmp_path / "saved")
    loaded = hc.load(tmp_path / "saved")
    assert loaded.points.equals(study.points) and str(loaded).startswith("\nslip:")
    with pytest.raises(ValueError, match="exists"):
        study.save(tmp_path / "saved")
    (tmp_path / "broken").mkdir()
    (tmp_path / "broken" / "summary.json").write_text("{")
    with pytest.raises(ValueError, match="summary.json"):
        hc.load(tmp_path / "broken")
    page = saved._repr_html_()
    assert page.startswith("<iframe srcdoc=") and "src=" not in page.split("srcdoc=", 1)[1].split("style=")[-1]
    assert "<script src" not in saved.report_html()
    files = study.plot(x="H", y="T", svg=True)
    assert [os.path.basename(f) for f in files] == ["T_H.png", "T_H.svg"]


def test_every_family_of_a_restart_is_in_the_answer_the_tables_and_the_folder(tmp_path):
    """The period-doubled family of a restart from PD4 (and of a run with period_doubling) is a family like any
    other: named, with its physical and stable ranges, the same numbers in the one-screen answer, Python's
    families, summary.json and a sweep's table row."""
    from hybridcont.sweeps import family_rows
    study = hc.run("slip", out=tmp_path / "A", progress=False)
    doubled = study.continue_from("PD4", out=tmp_path / "B", progress=False)
    name = "period-doubled backward hopping / forward hopping"
    assert "2 branches with physical orbits of 2" in str(doubled)
    families = doubled.families
    assert set(families.family) == {name}
    physical = families[families.kind == "physical"].iloc[0]
    stable = families[families.kind == "stable"].iloc[0]
    assert physical["from"] == pytest.approx(1.282699643, abs=1e-7) and physical["to"] == pytest.approx(1.427197748, abs=1e-8)
    assert stable["to"] == pytest.approx(1.282809324, abs=1e-8)
    assert "%s: physical H %.10g .. %.10g; stable H %.10g .. %.10g" % (
        name, physical["from"], physical["to"], stable["from"], stable["to"]) in re.sub(r"\n +", " ", str(doubled))
    assert doubled.summary["families"][0]["physical"][0]["from"] == physical["from"]
    rows = family_rows(doubled, "0", {"k": 40.0})
    assert [r["exists"] for r in rows if r["family"] == "hopping in place"] == [False]  # the model's, not here
    row = [r for r in rows if r["family"] == name][0]
    assert row["physical_from"] == physical["from"] and row["stable_to"] == stable["to"]
    assert row["physical_ranges"] == "%.17g..%.17g" % (physical["from"], physical["to"])
    # The same family in a whole run with period doubling, the same numbers.
    whole = hc.run("slip", out=tmp_path / "C", progress=False, period_doubling=True)
    same = whole.families[whole.families.family == name]
    assert list(same["from"]) == list(families["from"]) and list(same["to"]) == list(families["to"])


def test_a_folder_rebuilds_its_own_model_never_another_of_its_name(tmp_path):
    """A user's slip.toml with other physics, elsewhere: hc.load and the report use it, and refuse with the reason
    once it has changed; never the built-in SLIP."""
    text = open(os.path.join(MODELS, "slip.toml")).read()
    # Other physics: the leg swings twice as stiffly in flight (the start, at zero flight time, is the same).
    stiffer = text.replace('dalpha = "-alpha*w2"', 'dalpha = "-2*alpha*w2"')
    assert stiffer != text
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "slip.toml").write_text(stiffer)
    study = hc.run(str(tmp_path / "mine" / "slip.toml"), out=tmp_path / "out", progress=False, max_branches=8)
    assert study.summary["model_source"]["kind"] == "file"
    loaded = hc.load(tmp_path / "out")
    points = loaded.points
    flying = points[(points.physical == 1) & (points.t2 > 0.05) & (points.x2_dx.abs() > 0.05)].iloc[0]  # the leg swings
    branch, index = int(flying.branch), int(flying["index"])
    u = loaded.u(branch, index)
    assert np.abs(loaded.evaluate(branch, index)["r"]).max() < 1e-8  # an orbit of the user's model
    shipped = hc.model(os.path.join(MODELS, "slip.toml"))  # the same name and layout, the shipped physics
    assert np.abs(shipped.evaluate(u)["r"]).max() > 1e-3
    (tmp_path / "mine" / "slip.toml").write_text(stiffer + "# edited\n")
    with pytest.raises(ValueError, match="has changed since the study"):
        hc.load(tmp_path / "out").evaluate(branch, index)
    # The report of the changed folder says why it has no animations, and is still written.
    page = hc.load(tmp_path / "out").report_html()
    assert "study-data" in page


def test_a_model_object_is_rebuilt_from_where_it_was_made(tmp_path):
    """hc.run(hc.model(NAME)): the folder records the built-in model (or the model file) it was made from, and
    hc.load rebuilds it there, at the study's parameters."""
    ball = hc.model("bouncing-ball").with_parameters(g=2.0)
    hc.run(ball, out=tmp_path / "b", progress=False, max_branches=2)
    loaded = hc.load(tmp_path / "b")
    assert loaded.summary["model_source"]["kind"] == "builtin"
    assert loaded._model().parameters["g"] == 2.0  # at the study's parameters
    assert loaded.floquet(0, 1)["monodromy"].shape[0] >= 1
    shipped = hc.model(os.path.join(MODELS, "bouncing-ball.toml"))
    hc.run(shipped, out=tmp_path / "f", progress=False, max_branches=2)
    assert hc.load(tmp_path / "f").summary["model_source"]["kind"] == "file"


def test_a_rerun_leaves_nothing_of_the_previous_study(tmp_path):
    hc.run("slip", out=tmp_path / "r", progress=False, max_branches=4).plot()
    (tmp_path / "r" / ".report.html.x1Y2z3").write_text("a report write cut short")
    assert os.path.exists(tmp_path / "r" / "words.png") or os.path.exists(tmp_path / "r" / "figures.txt")
    drawn = (tmp_path / "r" / "figures.txt").read_text().split()
    assert drawn and all(os.path.exists(tmp_path / "r" / f) for f in drawn)
    hc.run("slip", out=tmp_path / "r", progress=False, max_branches=4, report=False)
    assert not [f for f in drawn if os.path.exists(tmp_path / "r" / f)]
    assert not os.path.exists(tmp_path / "r" / "report.html")
    assert not [f for f in os.listdir(tmp_path / "r") if f.endswith(".tmp") or f.startswith(".report.html.")]


def test_continuation_point_by_point():
    slip = hc.model("slip")
    study = hc.run(slip, progress=False, max_branches=4)
    u0 = study.u(2, 20)
    run = hc.continuation(slip, u0, max_points=12)
    points = list(run)
    assert len(points) == 12 and run.termination == "max-points"
    assert run.unknowns == slip.unknowns() == study.unknowns
    for p in points:  # every point is an orbit of the family: r = 0
        assert np.abs(slip.evaluate(p["u"], jacobian=False)["r"]).max() < 1e-9


def test_one_version():
    rc, out, _ = cli("--version")
    assert hc.__version__ in out
    assert hc.run("bouncing-ball", progress=False).summary["version"] == hc.__version__
    # The citation names the same version, and the changelog has its entry.
    source = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
    with open(os.path.join(source, "CITATION.cff")) as f:
        assert 'version: "%s"' % hc.__version__ in f.read()
    with open(os.path.join(source, "CHANGELOG.md")) as f:
        assert "## %s (" % hc.__version__ in f.read()


def test_ctrl_c_during_a_model_compile_ends_the_command_at_once(tmp_path):
    """A terminal's Ctrl-C (SIGINT to the foreground process group) while a model file is compiled: the command
    ends within seconds (it waited for the compiler before), and the next compile cleans what it left."""
    cache = tmp_path / "cache"
    env = dict(os.environ, HYBRIDCONT_CACHE=str(cache))
    model = os.path.join(os.path.dirname(__file__), "..", "..", "models", "bouncing-ball.toml")

    def run():
        return subprocess.Popen([TOOL, "run", model, "--quiet", "--out", str(tmp_path / "out")], env=env,
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    proc = run()
    deadline = time.time() + 60
    while time.time() < deadline and not (cache.exists() and any(p.suffix == ".cc" for p in cache.iterdir())):
        time.sleep(0.05)
    assert any(p.suffix == ".cc" for p in cache.iterdir()), "no compile under way"
    time.sleep(0.5)
    os.killpg(proc.pid, signal.SIGINT)
    start = time.time()
    proc.wait(timeout=30)
    assert time.time() - start < 5 and proc.returncode != 0
    left = [p for p in cache.iterdir() if p.suffix in (".cc", ".log") or ".so." in p.name]
    proc = run()  # compiles again, and removes what the interrupted compile left
    assert proc.wait(timeout=300) == 0
    assert not [p for p in left if p.exists()]


def test_multipliers_come_with_their_error(tmp_path):
    """Every physical point's multipliers carry their estimated error (the branch files' multiplier_error), small
    on the SLIP's ordinary orbits, and Model.floquet / Study.floquet give it too."""
    study = hc.run("slip", out=tmp_path / "s", progress=False)
    physical = study.points[study.points.physical == 1]
    assert len(physical) > 10
    assert (physical.multiplier_error >= 0).all() and (physical.multiplier_error < 1e-5).all()
    row = physical.iloc[len(physical) // 2]
    f = study.floquet(int(row.branch), int(row["index"]))
    assert f["ok"] and 0 <= f["multiplier_error"] < 1e-5
    assert not f["stability"].startswith("undetermined")
