"""Shared pieces of the Python tests: a small two-helix case and the command line's binary."""
import copy
import os
import subprocess

import pytest

BINARY = os.environ.get("STOKESRODS_BINARY", "")
SOURCE_DIR = os.environ.get("STOKESRODS_SOURCE_DIR",
                            os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))

HELIX = {"shape": "helix", "radius": 1e-3, "young_modulus": 10e6, "nodes": 21, "axis_length": 0.2,
         "pitch": 0.05, "helix_radius": 0.01, "clamped_nodes": 2, "omega_bar": 533}

SMALL = {
    "run": {"name": "small", "duration": 0.3, "time_step": 0.02, "output_interval": 0.1},
    "fluid": {"model": "rss"},
    "contact": {"enabled": True},
    "rods": [dict(HELIX, base=[0.0, 0.0, 0.0]), dict(HELIX, base=[0.04, 0.0, 0.0])],
}


@pytest.fixture
def small():
    return copy.deepcopy(SMALL)


def run_cli(*args):
    """(exit code, stderr) of the stokesrods binary."""
    if not BINARY:
        pytest.skip("STOKESRODS_BINARY not set (run through ctest)")
    p = subprocess.run([BINARY, *map(str, args)], capture_output=True, text=True,
                       env=dict(os.environ, OMP_NUM_THREADS="1"))
    return p.returncode, p.stderr
