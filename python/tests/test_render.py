"""stokesrods render and stokesrods plot on a small run: the files, the exit codes, pictures
that are not blank."""
import os
import subprocess

import numpy as np
import pytest

import stokesrods
from conftest import run_cli


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    from conftest import SMALL
    out = tmp_path_factory.mktemp("render") / "small"
    config = dict(SMALL, flow_field={"times": [0.2], "origin": [-0.02, 0.0, -0.22],
                                     "u": [0.08, 0.0, 0.0], "v": [0.0, 0.0, 0.24],
                                     "resolution": [8, 12]})
    stokesrods.run(config, output=out)
    return out


def inked(path):
    """Fraction of pixels that are not white."""
    import matplotlib.image
    image = matplotlib.image.imread(path)[..., :3]
    return float(np.mean(image.min(axis=2) < 0.9))


def test_render_writes_views_flow_and_video(run_dir):
    code, err = run_cli("render", run_dir, "--max-frames", 3, "--fps", 4)
    assert code == 0, err
    views, flow, video = (run_dir / "render" / name for name in ("views.png", "flow.png", "run.mp4"))
    assert 0.02 < inked(views) < 0.6 and 0.2 < inked(flow)
    frames = subprocess.run(["ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0",
                             "-show_entries", "stream=nb_read_frames", "-of", "csv=p=0", video],
                            capture_output=True, text=True, check=True).stdout
    assert int(frames) == 3  # of t = 0, 0.1, 0.2, 0.3: every 2nd (0, 0.2) and the last


def test_render_colours_by_a_field(run_dir):
    code, err = run_cli("render", run_dir, "--no-video", "--color", "hydrodynamic_force",
                        "--output-dir", run_dir / "by_drag")
    assert code == 0, err
    assert inked(run_dir / "by_drag" / "views.png") > 0.02
    code, err = run_cli("render", run_dir, "--no-video", "--color", "pressure")
    assert code == 2 and "no such point data" in err and "contact_force" in err


def test_plot_columns(run_dir):
    code, err = run_cli("plot", run_dir, "delta_b_over_R", "min_distance", "--x", "t_bar")
    assert code == 0, err
    assert inked(run_dir / "plot_delta_b_over_R_min_distance.png") > 0.02
    code, err = run_cli("plot", run_dir, "nope")
    assert code == 2 and "no column 'nope'" in err


def test_bad_run_directory(tmp_path):
    code, err = run_cli("render", tmp_path / "missing")
    assert code == 2 and "not a directory" in err
    code, _ = run_cli("render")
    assert code == 2


def test_colour_range_spans_what_the_segments_show():
    # A field on one node only: its two segments show half of it (the mean of their two nodes),
    # so the colour bar tops at half the node value and the brightest tube is the top colour.
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from stokesrods.render import field_range
    from stokesrods.tubes import draw_rods, segment_values
    rods = [np.column_stack([np.zeros(5), np.zeros(5), -0.01 * np.arange(5)]),
            np.column_stack([0.02 + np.zeros(4), np.zeros(4), -0.01 * np.arange(4)])]
    force = np.zeros((9, 3))
    force[2] = [0.0, 3.0, 4.0]  # |f| = 5 at rod 1, node 2
    data = {"contact_force": force}
    shown = segment_values(rods, data, "contact_force")
    np.testing.assert_array_equal(shown[0], [0.0, 2.5, 2.5, 0.0])
    np.testing.assert_array_equal(shown[1], [0.0, 0.0, 0.0])
    assert field_range([(0.0, rods, data)], "contact_force") == (0.0, 2.5)
    fig, ax = plt.subplots()
    mappable = draw_rods(ax, rods, [1e-3, 1e-3], 0, data, "contact_force", (0.0, 2.5))
    assert mappable.norm(2.5) == 1.0
    plt.close(fig)
