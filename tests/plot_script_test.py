"""Tests of python/hybridcont_plot.py on small synthetic results folders.

The script knows no model: a folder whose summary.json carries a presentation (title, figures, drawing)
and whose orbit files carry phase and draw.<point>.x/.y columns must give the declared figures and the
key frames for a model the script has never heard of; an older folder without a presentation still gets
the generic figures; a broken summary.json ends with one line naming the file, exit status 2.

Run with ``/usr/bin/python3 -m pytest -q tests/plot_script_test.py`` (no network).
"""

import csv
import importlib.util
import json
import math
import os
import subprocess
import sys

import pytest

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "python", "hybridcont_plot.py")
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def write_csv(path, header, rows):
    with open(path, "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(header)
        writer.writerows(rows)


def branch_rows(sign):
    """A short branch of a two-phase hopper-like model: H rises, durations change, half of it physical."""
    rows = []
    for i in range(12):
        H = 1.0 + 0.05 * i
        t1, t2, t3 = 0.5 - 0.01 * i, sign * 0.1 * i, 0.5 - 0.012 * i
        rows.append([i, H, t1 + t2 + t3, 0.0, t1, t2, t3, 0.9 - 0.01 * i, t2 - t1 - t3,
                     1 if (sign > 0 and i >= 2) else 0, "physical" if (sign > 0 and i >= 2) else "reversed-time",
                     1 if i < 6 else 0])
    return rows


BRANCH_HEADER = ["index", "H", "T", "xi", "t1", "t2", "t3", "x1_l", "asym", "physical", "classification",
                 "stable"]


def orbit_rows():
    """One period: stance (the foot on the ground, the body above it), flight (the body on a parabola,
    the leg hanging below), stance again.  The body moves forward, so X is in the coordinates."""
    rows = []
    t_stance, t_flight = 0.4, 1.0
    n = 12
    for seg, phase, t0, dur in ((1, "stance", 0.0, t_stance), (2, "flight", t_stance, t_flight),
                                (3, "stance", t_stance + t_flight, t_stance)):
        for i in range(n + 1):
            t = t0 + dur * i / n
            X = 0.3 * t
            if phase == "stance":
                l = 1.0 - 0.2 * math.sin(math.pi * i / n)
                row = [t, seg, phase, l, "", X, l, X + 0.1, 0.0]
            else:
                y = 1.0 + 0.5 * math.sin(math.pi * i / n)
                row = [t, seg, phase, "", y, X, y, X + 0.1, y - 1.0]
            rows.append(row)
    return rows


ORBIT_HEADER = ["t", "segment", "phase", "stance.l", "flight.y", "draw.body.x", "draw.body.y", "draw.foot.x",
                "draw.foot.y"]


def summary(with_presentation=True):
    s = {
        "model": "toy-hopper",
        "parameters": {"k": 20.0, "l0": 1.0},
        "phases": [{"name": "stance", "states": ["l"]}, {"name": "flight", "states": ["y"]}],
        "unknowns": ["t1", "t2", "t3", "x1_l", "xi", "H"],
        "branches": [
            {"id": 0, "file": "branch-0.csv", "parent": 0, "points": 12, "termination": "bound-reached",
             "direction": 1},
            {"id": 1, "file": "branch-1.csv", "parent": 0, "points": 12, "termination": "bound-reached",
             "direction": -1},
        ],
        "special_points": [
            {"id": 0, "type": "start", "branch": -1, "index": -1, "H": 1.0, "T": 1.0, "status": "located",
             "u": [0.5, 0.0, 0.5, 0.9, 0.0, 1.0]},
            {"id": 1, "type": "SB", "branch": 0, "index": 4, "H": 1.21, "T": 1.3, "status": "located",
             "u": [0.458, 0.42, 0.45, 0.858, 0.0, 1.21]},
            {"id": 2, "type": "TP", "branch": 1, "index": 7, "H": 1.36, "T": 0.2, "status": "bracketed"},
        ],
        "orbits": [{"file": "orbit-0.csv", "branch": 0, "index": 6, "H": 1.3, "T": 1.8,
                    "label": "forward hopping"}],
    }
    if with_presentation:
        s["presentation"] = {
            "title": "toy hopper",
            "quantities": ["asym"],
            "families": ["forward hopping", "backward hopping"],
            "figures": [
                {"file": "toy_durations.png", "title": "stance durations over flight time", "x": "t2",
                 "y": ["t1", "t3"], "zoom": False},
                {"file": "toy_zoom.png", "title": "zoom on the special points", "x": "T", "y": ["H"],
                 "zoom": True},
                {"file": "toy_asym.png", "title": "asymmetry", "x": "T", "y": ["asym"], "zoom": False},
            ],
            "drawing": {"ground": True, "mass_radius": 0.06,
                        "phases": {"stance": {"lines": [["foot", "body"]], "masses": ["body"]},
                                   "flight": {"lines": [["foot", "body"]], "masses": ["body"]}}},
        }
    return s


@pytest.fixture
def results(tmp_path):
    """A complete results folder in the current format; returns its path."""
    folder = tmp_path / "results"
    folder.mkdir()
    with open(folder / "summary.json", "w") as f:
        json.dump(summary(), f, indent=1)
    write_csv(folder / "branch-0.csv", BRANCH_HEADER, branch_rows(+1))
    write_csv(folder / "branch-1.csv", BRANCH_HEADER, branch_rows(-1))
    write_csv(folder / "orbit-0.csv", ORBIT_HEADER, orbit_rows())
    return folder


def run(folder, *args):
    proc = subprocess.run([sys.executable, SCRIPT, str(folder)] + list(args), capture_output=True, text=True,
                          timeout=300)
    return proc.returncode, proc.stdout, proc.stderr


def assert_png(path):
    assert path.is_file(), "%s was not written" % path.name
    with open(path, "rb") as f:
        assert f.read(8) == PNG_MAGIC, "%s is not a PNG file" % path.name
    assert path.stat().st_size > 2000, "%s is suspiciously small" % path.name


def test_presentation_gives_declared_figures_and_key_frames(results):
    code, out, err = run(results)
    assert code == 0, err
    assert "Traceback" not in err
    for name in ("H_T.png", "toy_durations.png", "toy_zoom.png", "toy_asym.png", "keyframes.png"):
        assert_png(results / name)
        assert str(results / name) in out.splitlines()
    assert not (results / "H_T_xi.png").exists()  # xi is zero everywhere
    assert err == "", err


def test_without_presentation_generic_figures_and_one_warning(results):
    s = summary(with_presentation=False)
    with open(results / "summary.json", "w") as f:
        json.dump(s, f)
    code, out, err = run(results)
    assert code == 0, err
    assert_png(results / "H_T.png")
    for name in ("toy_durations.png", "keyframes.png"):
        assert not (results / name).exists()
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1 and "presentation" in lines[0] and "warning" in lines[0], err
    assert out.splitlines() == [str(results / "H_T.png")]


def test_orbit_without_draw_columns_skips_key_frames_only(results):
    header = [c for c in ORBIT_HEADER if not c.startswith("draw.")]
    keep = [ORBIT_HEADER.index(c) for c in header]
    write_csv(results / "orbit-0.csv", header, [[r[i] for i in keep] for r in orbit_rows()])
    code, out, err = run(results)
    assert code == 0, err
    assert_png(results / "toy_durations.png")
    assert not (results / "keyframes.png").exists()
    assert "orbit-0.csv" in err and "draw" in err
    assert "Traceback" not in err


def test_corrupted_summary_exits_2_naming_the_file(results):
    with open(results / "summary.json", "w") as f:
        f.write(json.dumps(summary())[:200])  # cut off mid-object
    code, out, err = run(results)
    assert code == 2
    assert out == ""
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "summary.json" in lines[0], err


@pytest.fixture(scope="module")
def plot():
    """The script as a module (its main() and drawing helpers)."""
    spec = importlib.util.spec_from_file_location("hybridcont_plot", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("edit, field", [
    (lambda s: s["presentation"]["figures"][0].pop("x"), "presentation.figures[0].x"),
    (lambda s: s["presentation"]["figures"][1].update(y=[3]), "presentation.figures[1].y"),
    (lambda s: s["presentation"]["figures"][0].update(zoom="yes"), "presentation.figures[0].zoom"),
    (lambda s: s["presentation"]["drawing"].update(mass_radius="big"), "presentation.drawing.mass_radius"),
    (lambda s: s["presentation"]["drawing"]["phases"]["stance"].update(lines=[["foot", 2]]),
     "presentation.drawing.phases.stance.lines[0]"),
    (lambda s: s.update(presentation=[]), "presentation"),
    (lambda s: s["branches"][1].update(file=7), "branches[1].file"),
    (lambda s: s["special_points"][1].update(branch=[0]), "special_points[1].branch"),
    (lambda s: s.pop("branches"), "branches"),
])
def test_malformed_field_exits_2_naming_file_and_field(plot, results, capsys, edit, field):
    # in-process: the script stops before drawing, so importing matplotlib once serves every case
    s = summary()
    edit(s)
    with open(results / "summary.json", "w") as f:
        json.dump(s, f)
    code = plot.main([str(results)])
    out, err = capsys.readouterr()
    assert code == 2, err
    assert out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert "summary.json" in lines[0] and field in lines[0], err


def test_key_frame_shapes_follow_the_phase_drawing(plot, results):
    """A sample draws its own phase's lines and masses at the draw.* coordinates, nothing else."""
    rows = plot.load_orbit(str(results / "orbit-0.csv"), summary()["phases"])
    # the stance's last sample lies a rounding error past the flight's first: segments stay in order
    assert [r[1] for r in rows] == sorted(r[1] for r in rows)
    drawing = plot.Drawing(plot.read_presentation(summary(), "summary.json")["drawing"], summary()["phases"])
    t, seg, phase, points = plot.state_at(rows, 0.9)  # mid-flight
    assert phase == "flight" and seg == 2
    shapes = drawing.shapes((t, seg, phase, points), "blue")
    lines = [s for s in shapes if s[0] == "line"]
    circles = [s for s in shapes if s[0] == "circle"]
    assert len(lines) == 1 and len(circles) == 1
    body, foot = points["body"], points["foot"]
    assert lines[0][1] == [foot, body]
    assert circles[0][1] == body and circles[0][2] == pytest.approx(0.06)
    assert body[0] == pytest.approx(0.3 * 0.9, abs=1e-9)  # the horizontal motion is in the coordinates
    assert body[1] - foot[1] == pytest.approx(1.0, abs=1e-9)
    # a phase without a drawing draws nothing
    assert drawing.shapes((t, seg, "swing", points), "blue") == []


@pytest.mark.parametrize("damage, message", [
    (lambda folder: os.remove(folder / "branch-1.csv"), "branch-1.csv, which is missing"),
    (lambda folder: open(folder / "branch-0.csv", "a").write("garbage,,,x\n"), "branch-0.csv:14: 4 cells"),
    (lambda folder: os.remove(folder / "orbit-0.csv"), "orbit-0.csv, which is missing"),
    (lambda folder: open(folder / "summary.json", "w").write("[" * 100000), "nested too deeply"),
])
def test_damaged_folder_exits_2_before_drawing(plot, results, capsys, damage, message):
    damage(results)
    code = plot.main([str(results)])
    out, err = capsys.readouterr()
    assert code == 2, err
    assert out == ""
    assert message in err and "Traceback" not in err, err
    assert not list(results.glob("*.png")), "figures drawn from a damaged folder"


# --------------------------------------------------------------------------------------------------------
# figures for papers: families, labels, formats, any two columns
# --------------------------------------------------------------------------------------------------------

def with_families(folder):
    """The folder's summary with the writer's family names: branch 0 is forward hopping, branch 1 has no
    physical orbit (no name)."""
    with open(folder / "summary.json") as f:
        s = json.load(f)
    s["branches"][0]["family"] = "forward hopping"
    with open(folder / "summary.json", "w") as f:
        json.dump(s, f)
    return folder


def test_legend_names_families_not_branches(plot, results):
    res = plot.Results(str(with_families(results)))
    fig, ax = plot.plt.subplots()
    drawn, styles = plot.projection(ax, res, "T", "H")
    labels = [h.get_label() for h in plot.legend_handles(res, drawn, styles, stable=True)]
    assert labels[:2] == ["forward hopping", plot.OTHER_LABEL]
    assert not any(label.startswith("branch") for label in labels)
    # the family takes the first of Okabe and Ito's colours; the unnamed branch is light grey
    assert res.by_id[0]["colour"] == plot.OKABE_ITO[0] and res.by_id[1]["colour"] == plot.OTHER_COLOUR
    # only the special point on the physical stretch is labelled (SB1 at index 4; the TP lies where no
    # orbit is physical)
    assert [text for _, _, text in ax._hc_labels] == ["SB1"]
    plot.plt.close(fig)


def test_labels_of_coincident_points_merge_and_no_two_labels_overlap(plot):
    fig, ax = plot.plt.subplots(figsize=(4, 3))
    ax.set_xlim(0, 10)
    ax.set_ylim(0, 10)
    points = [(5, 5, "SB1"), (5, 5, "PD3"), (5.05, 5.05, "BP2"), (5.3, 5.0, "TP4"), (5.0, 5.3, "TP5"),
              (5.3, 5.3, "GR6")]
    ax._hc_labels = list(points)
    plot.place_labels(ax)
    texts = [t for t in ax.texts]
    assert sorted(t.get_text() for t in texts) == ["BP2/PD3/SB1", "GR6", "TP4", "TP5"]
    fig.canvas.draw()
    boxes = [t.get_window_extent() for t in texts]
    for i in range(len(boxes)):
        for j in range(i + 1, len(boxes)):
            assert not boxes[i].overlaps(boxes[j]), (texts[i].get_text(), texts[j].get_text())
    plot.plt.close(fig)


def test_any_two_columns_and_vector_formats(results):
    rc, out, err = run(results, "--x", "t2", "--y", "asym", "--svg", "--pdf")
    assert rc == 0, err
    assert out.split() == [str(results / ("asym_t2.%s" % ext)) for ext in ("png", "svg", "pdf")]
    with open(results / "asym_t2.pdf", "rb") as f:
        assert f.read(5) == b"%PDF-"
    with open(results / "asym_t2.svg") as f:
        assert "<svg" in f.read(2000)
    assert not (results / "H_T.png").exists()  # one diagram asked for, nothing else drawn
    rc, out, err = run(results, "--x", "t2", "--y", "speed")
    assert rc == 2 and out == ""
    assert "no branch file in %s has a column 'speed'" % results in err and "asym" in err
    rc, _, err = run(results, "--x", "t2")
    assert rc == 2 and "--x and --y go together" in err


def test_forced_system_diagram_shows_a_state_over_the_parameter(plot, results):
    """Families in a forcing frequency w have T = 2π/w: the main diagram draws the section's first state
    over w (x1_l here), named after its axes, not T."""
    with open(results / "summary.json") as f:
        s = json.load(f)
    s["options"] = {"free": ["w"]}
    s["unknowns"] = ["t1", "t2", "t3", "x1_l", "w"]
    for sp in s["special_points"]:
        sp.pop("u", None)
    with open(results / "summary.json", "w") as f:
        json.dump(s, f)
    for k in (0, 1):
        path = results / ("branch-%d.csv" % k)
        with open(path) as f:
            rows = list(csv.reader(f))
        header = rows[0] + ["w"]
        body = []
        for r in rows[1:]:
            w = 0.8 + 0.01 * int(r[0])
            r[2] = repr(2 * math.pi / w)
            body.append(r + [repr(w)])
        write_csv(path, header, body)
    res = plot.Results(str(results))
    assert plot.main_diagram_axes(res) == ("w", "x1_l", "x1_l_w")
    assert plot.axis_label("x1_l", res) == r"$l$ at the start of stance  (x1_l)"
