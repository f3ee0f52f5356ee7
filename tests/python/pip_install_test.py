"""The package as a user installs it: `pip wheel --no-build-isolation --no-index .` builds a wheel (offline: no
package index), which installs into a fresh virtual environment (made with --system-site-packages, which lends it
Debian's NumPy, pandas and Dask) with `--no-index`; from that environment alone the package runs a study, and
its `hybridcont` command runs one, compiles a model file (against the headers the wheel carries) and runs a
two-point sweep. The wheel is made from the package the build laid out (HYBRIDCONT_PREBUILT_PACKAGE, setup.py),
so the test checks the packaging of what the other tests test without building again; setup.py's CMake path
lays out the same folder."""
import glob
import json
import os
import subprocess

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, os.pardir))


def test_a_wheel_installs_offline_and_its_package_and_command_work(tmp_path):
    package = os.environ["HYBRIDCONT_PACKAGE_DIR"]
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "HYBRIDCONT_BIN")}
    env["HYBRIDCONT_PREBUILT_PACKAGE"] = package
    env["HYBRIDCONT_CACHE"] = str(tmp_path / "cache")  # a fresh cache: the model file is compiled here
    wheels = tmp_path / "wheels"
    proc = subprocess.run(["/usr/bin/python3", "-m", "pip", "wheel", "--no-build-isolation", "--no-index", "--no-deps",
                           "--quiet", "-w", str(wheels), ROOT], capture_output=True, text=True, env=env,
                          cwd=str(tmp_path))
    assert proc.returncode == 0, proc.stdout + proc.stderr
    [wheel] = glob.glob(str(wheels / "hybridcont-*.whl"))

    venv = tmp_path / "venv"
    subprocess.run(["/usr/bin/python3", "-m", "venv", "--system-site-packages", str(venv)], check=True)
    python, command = str(venv / "bin" / "python"), str(venv / "bin" / "hybridcont")
    env.pop("HYBRIDCONT_PREBUILT_PACKAGE")
    proc = subprocess.run([python, "-m", "pip", "install", "--no-index", "--no-deps", "--quiet", wheel],
                          capture_output=True, text=True, env=env, cwd=str(tmp_path))
    assert proc.returncode == 0, proc.stdout + proc.stderr

    check = ("import hybridcont as hc, os\n"
             "assert hc.__file__.startswith(%r), hc.__file__\n"
             "s = hc.run('bouncing-ball', progress=False)\n"
             "print(hc.__version__, s.status, len(s.points), os.path.exists(os.path.join(s.path, 'report.html')))\n"
             % str(venv))
    proc = subprocess.run([python, "-c", check], capture_output=True, text=True, env=env, cwd=str(tmp_path))
    assert proc.returncode == 0, proc.stderr
    version, status, points, report = proc.stdout.split()
    assert status == "completed" and int(points) > 10 and report == "True"

    # The command: a built-in model, then a model file of the wheel's own (compiled, not interpreted).
    proc = subprocess.run([command, "--version"], capture_output=True, text=True, env=env, cwd=str(tmp_path))
    assert proc.returncode == 0 and version in proc.stdout, proc.stdout + proc.stderr
    proc = subprocess.run([command, "run", "slip", "--out", "slip", "--quiet"], capture_output=True, text=True,
                          env=env, cwd=str(tmp_path))
    assert proc.returncode == 0 and "slip: 5 branches with physical orbits" in proc.stdout, proc.stderr
    assert os.path.exists(tmp_path / "slip" / "report.html")
    where = subprocess.run([python, "-c", "import hybridcont, os; print(os.path.dirname(hybridcont.__file__))"],
                           capture_output=True, text=True, env=env, cwd=str(tmp_path), check=True).stdout.strip()
    models = os.path.join(where, "data", "models")
    proc = subprocess.run([command, "run", os.path.join(models, "forced-impact-oscillator.toml"), "--out", "oscillator",
                           "--quiet"], capture_output=True, text=True, env=env, cwd=str(tmp_path))
    assert proc.returncode == 0, proc.stderr
    assert "compiling model 'forced-impact-oscillator'" in proc.stderr, proc.stderr
    assert "interpret" not in proc.stderr, proc.stderr

    # A two-point sweep on Dask, from the environment alone.
    proc = subprocess.run([command, "sweep", "slip", "--grid", "k=30:40:2", "--out", "sweep", "--workers", "1"],
                          capture_output=True, text=True, env=env, cwd=str(tmp_path), timeout=600)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    with open(tmp_path / "sweep" / "sweep.json") as f:
        assert json.load(f)["grid"] == {"k": [30.0, 40.0]}
