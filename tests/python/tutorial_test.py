"""docs/python.md runs: its ```python blocks, in order, in one namespace (a notebook written out), with the
package built into build/python. The figures it draws go to a temporary folder, or to docs/figures with
HYBRIDCONT_TUTORIAL_FIGURES=docs/figures (how the page's figures were made)."""
import os
import re

import pytest

DOC = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, os.pardir, "docs", "python.md")


def blocks():
    with open(DOC, encoding="utf-8") as f:
        return re.findall(r"```python\n(.*?)```", f.read(), re.S)


def test_the_tutorial_runs(tmp_path, monkeypatch, capsys):
    if "HYBRIDCONT_TUTORIAL_FIGURES" not in os.environ:
        monkeypatch.setenv("HYBRIDCONT_TUTORIAL_FIGURES", str(tmp_path / "figures"))
    code = blocks()
    assert len(code) >= 6
    namespace = {"__name__": "tutorial"}
    for k, block in enumerate(code):
        try:
            exec(compile(block, "%s, block %d" % (DOC, k + 1), "exec"), namespace)
        except Exception as e:  # noqa: BLE001 - name the block that failed
            pytest.fail("docs/python.md block %d failed: %s: %s" % (k + 1, type(e).__name__, e))
    out = capsys.readouterr().out
    assert "hopping in place (branch 2)" in out and "long-step gait" in out
    figures = os.environ["HYBRIDCONT_TUTORIAL_FIGURES"]
    for name in ("python-slip-speed.png", "python-compass-gait.png"):
        assert os.path.getsize(os.path.join(figures, name)) > 10000
