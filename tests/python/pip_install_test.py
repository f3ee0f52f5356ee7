"""`pip install --no-build-isolation --no-index .` into a virtual environment made with --system-site-packages
(offline: no package index), then the installed package runs a study. The package installed is the one the
build laid out (HYBRIDCONT_PREBUILT_PACKAGE, setup.py), so the test checks the packaging of what the other
tests test without building again; setup.py's CMake path is the same copy after `cmake --build`."""
import os
import subprocess
import sys

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, os.pardir))


def test_pip_installs_the_package_into_a_virtual_environment(tmp_path):
    package = os.environ["HYBRIDCONT_PACKAGE_DIR"]
    venv = tmp_path / "venv"
    subprocess.run(["/usr/bin/python3", "-m", "venv", "--system-site-packages", str(venv)], check=True)
    python = str(venv / "bin" / "python")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["HYBRIDCONT_PREBUILT_PACKAGE"] = package
    proc = subprocess.run([python, "-m", "pip", "install", "--no-build-isolation", "--no-index", "--quiet", ROOT],
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
