"""stokesrods.run: the same case as the command line, the same outputs, the same errors."""
import json
import tomllib

import numpy as np
import pytest

import stokesrods
from conftest import run_cli


def write_toml(path, config):
    """A dict of the schema as a TOML file, through the module's own reader and writer."""
    path.write_text(stokesrods.resolve_config(config))
    return path


def test_run_from_a_dict_matches_the_command_line(tmp_path, small):
    toml = write_toml(tmp_path / "small.toml", small)
    code, err = run_cli("run", toml, "--output", tmp_path / "cli")
    assert code == 0, err
    result = stokesrods.run(small, output=tmp_path / "py")
    cli = stokesrods.load(tmp_path / "cli")
    assert result.status == "completed"
    assert list(result.timeseries) == list(cli.timeseries)
    # One thread, the same code: the same numbers, digit for digit as written.
    for name, column in cli.timeseries.items():
        np.testing.assert_array_equal(result.timeseries[name], column, err_msg=name)
    assert result.summary["final"] == cli.summary["final"]
    assert result.summary["steps"] == 15


def test_result_arrays(tmp_path, small):
    result = stokesrods.run(small, output=tmp_path / "out")
    assert len(result.timeseries["time"]) == 4  # t = 0, 0.1, 0.2, 0.3
    np.testing.assert_allclose(result.timeseries["time"], [0.0, 0.1, 0.2, 0.3], rtol=1e-12)
    np.testing.assert_allclose(result.frame_times, result.timeseries["time"], rtol=1e-9)
    assert len(result.positions) == 4 and [x.shape for x in result.positions[-1]] == [(21, 3)] * 2
    # The last frame's tip is the timeseries' last rod1_end (frames keep 10 significant digits).
    tip = result.positions[-1][0][-1]
    np.testing.assert_allclose(tip, [result.timeseries[f"rod1_end_{a}"][-1] for a in "xyz"],
                               rtol=0, atol=1e-10)
    drag = result.forces("hydrodynamic_force")[-1]
    assert [f.shape for f in drag] == [(21, 3)] * 2 and np.abs(drag[0]).max() > 0
    with open(tmp_path / "out" / "summary.json") as f:
        assert result.summary == json.load(f)


def test_overrides_as_dict_and_as_strings(tmp_path, small):
    a = stokesrods.resolve_config(small, overrides={"rods.2.omega_bar": 400, "fluid.model": "rft"})
    b = stokesrods.resolve_config(small, overrides=["rods.2.omega_bar=400", "fluid.model=rft"])
    assert a == b
    resolved = tomllib.loads(a)
    assert resolved["fluid"]["model"] == "rft"
    assert [r["omega_bar"] for r in resolved["rods"]] == [533, 400]


@pytest.mark.parametrize("key, value", [("rods.radius", -1.0), ("run.time_step", "fast"),
                                        ("fluid.model", "stokes"), ("rods.nodes", 2)])
def test_bad_input_raises_value_error_with_the_cli_message(tmp_path, small, key, value):
    toml = write_toml(tmp_path / "small.toml", small)
    with pytest.raises(ValueError) as info:
        stokesrods.run(str(toml), overrides={key: value}, output=tmp_path / "py")
    text = json.dumps(value) if isinstance(value, str) else repr(value)
    code, err = run_cli("run", toml, "--set", f"{key}={text}", "--output", tmp_path / "cli")
    assert code == 2
    assert err.strip() == f"error: invalid input: {info.value}"


def test_unknown_key_in_a_dict(small):
    small["rods"][0]["colour"] = "red"
    with pytest.raises(ValueError, match=r"<dict>: rods.1.colour: unknown key"):
        stokesrods.Simulation(small)
    with pytest.raises(ValueError, match=r"cannot be given as a Python object"):
        stokesrods.Simulation({"run": {"name": object()}, "rods": [{}]})


def test_progress_callback(tmp_path, small):
    seen = []
    stokesrods.run(small, output=tmp_path / "out", progress=lambda *p: seen.append(p))
    assert seen and seen[-1][0] == pytest.approx(0.3) and seen[-1][3] == 15
