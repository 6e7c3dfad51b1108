"""examples/python/ run (each with --quick)."""
import os
import subprocess
import sys

import pytest

from conftest import SOURCE_DIR


@pytest.mark.parametrize("script", ["fig1.py", "buckling_sweep.py", "controller.py"])
def test_example_runs(tmp_path, script):
    path = os.path.join(SOURCE_DIR, "examples", "python", script)
    done = subprocess.run([sys.executable, path, "--quick"], cwd=tmp_path, capture_output=True,
                          text=True, env=dict(os.environ, OMP_NUM_THREADS="1"), timeout=600)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip()
