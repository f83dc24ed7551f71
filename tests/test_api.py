"""The README's "Use it from Python" example, run exactly as printed."""
from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def _example() -> str:
    text = README.read_text()
    section = text[text.index("## Use it from Python"):]
    section = section[:section.index("\n## ", 10)]
    blocks = re.findall(r"```python\n(.*?)```", section, flags=re.S)
    assert len(blocks) == 1
    return blocks[0]


def test_the_readme_python_example_runs_as_printed(tmp_path):
    """A network that is not in the package (four phase oscillators) drives the body through
    the one controller: it walks forwards (the CPG classifier names its pattern a walk, the
    body covers ground), and the video and the recording are written."""
    script = tmp_path / "example.py"
    script.write_text(_example())
    r = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True,
                       text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-2000:]
    physical, cpg, speed = r.stdout.split()[:3]
    assert cpg == "walk" and float(speed) > 0.3
    assert physical in ("walk", "none")
    # the README says what the block prints: it must be what it does print
    said = re.search(r"it prints `([^`]*?) \[\.\.\.\]`", README.read_text()).group(1)
    assert r.stdout.startswith(said), (said, r.stdout[:80])
    assert (tmp_path / "phase_walk.mp4").stat().st_size > 50_000
    assert (tmp_path / "phase_walk.rrd").stat().st_size > 100_000
    assert "WARN" not in r.stderr
