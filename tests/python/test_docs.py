"""docs/python.md's session runs as written: from a synthetic capture to a solved scene, a relit
render close to the truth, a plot and a glTF export."""

import os
import re
import subprocess
import sys


def session_code(source_dir):
    text = (source_dir / "docs" / "python.md").read_text()
    section = text.split("## A session", 1)[1]
    match = re.search(r"```python\n(.*?)```", section, re.S)
    assert match, "docs/python.md has no session code"
    return match.group(1)


def test_the_session_of_docs_python_md_runs_and_relights(source_dir, tmp_path):
    result = subprocess.run([sys.executable, "-c", session_code(source_dir)], cwd=tmp_path,
                            capture_output=True, text=True, env=dict(os.environ), timeout=600)
    assert result.returncode == 0, result.stderr[-3000:]
    out = result.stdout
    found = re.search(r"relit vs truth: mean ratio \[([0-9. ]+)\], median block difference "
                      r"([0-9.]+)", out)
    assert found, out
    ratios = [float(v) for v in found.group(1).split()]
    assert all(abs(r - 1) < 0.03 for r in ratios), out
    assert float(found.group(2)) < 0.15, out
    refined = float(re.search(r"render residual: paper [0-9.]+, refined ([0-9.]+)", out).group(1))
    assert refined < 0.3, out
    assert (tmp_path / "session.png").stat().st_size > 10000
    assert (tmp_path / "solved_gltf" / "export_report.json").exists()
