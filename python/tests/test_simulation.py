"""stokesrods.Simulation: stepping, controls between steps and checkpoints."""
import numpy as np
import pytest

import stokesrods


def trajectory(sim, steps):
    sim.step(steps)
    return np.vstack([sim.positions(k) for k in range(1, sim.num_rods + 1)])


def test_stepping_reproduces_run(tmp_path, small):
    result = stokesrods.run(small, output=tmp_path / "out")
    sim = stokesrods.Simulation(small)
    assert sim.time == 0 and sim.time_step == 0.02
    sim.step(15)
    assert sim.time == pytest.approx(0.3) and sim.steps == 15
    # A run forgets its reused Newton factors at its restart points (exact resume), a Simulation
    # keeps them: the two agree to the Newton tolerance (1e-8 of the force scale), not digit for digit.
    final = result.summary["final"]
    for name, value in sim.observables().items():
        if value == value and name != "newton_iterations":  # not NaN
            assert value == pytest.approx(final[name], rel=1e-8, abs=1e-12), name
    np.testing.assert_allclose(sim.positions(2), result.positions[-1][1], rtol=0, atol=1e-10)
    load = sim.clamp_load(1)
    np.testing.assert_allclose(load["force"], [final[f"rod1_force_{a}"] for a in "xyz"], rtol=1e-8)
    assert sim.velocities(1).shape == (21, 3) and sim.twist_angles(1).shape == (20,)
    with pytest.raises(IndexError, match="rod 3 does not exist"):
        sim.positions(3)


def test_set_omega_between_steps_equals_configured_rate(small):
    w = 2.0
    fixed = dict(small)
    fixed["rods"] = [dict(r) for r in small["rods"]]
    for r in fixed["rods"]:
        r.pop("omega_bar")
        r["omega"] = w
    reference = trajectory(stokesrods.Simulation(fixed), 4)
    controlled = stokesrods.Simulation(small)
    controlled.set_omega(1, w)
    controlled.set_omega(2, w)
    assert controlled.omega(2) == w
    np.testing.assert_array_equal(trajectory(controlled, 4), reference)
    # And the rate matters: the default rate gives another shape.
    assert np.abs(trajectory(stokesrods.Simulation(small), 4) - reference).max() > 1e-6


def test_set_loads_between_steps_equals_configured_loads(small):
    force = [0.0, 2e-4, 0.0]
    loaded = dict(small)
    loaded["rods"] = [dict(small["rods"][0], loads=[{"node": 20, "force": force}]), small["rods"][1]]
    reference = stokesrods.Simulation(loaded)
    reference.step(2)
    controlled = stokesrods.Simulation(small)
    controlled.step(1)
    controlled.set_loads(1, {20: force})
    unloaded = stokesrods.Simulation(small)
    unloaded.step(2)
    controlled.step(1)
    assert list(controlled.loads(1)) == [20]
    # Loaded from step 2 on: neither the unloaded run nor the run loaded from the start.
    tip = lambda s: s.positions(1)[-1]  # noqa: E731
    assert tip(controlled)[1] > tip(unloaded)[1] + 1e-7
    assert tip(reference)[1] > tip(controlled)[1] + 1e-7
    with pytest.raises(IndexError, match="no node 21"):
        controlled.set_loads(1, {21: force})


def test_checkpoint_round_trip(tmp_path, small):
    sim = stokesrods.Simulation(small)
    sim.step(3)
    sim.save_checkpoint(str(tmp_path / "c.bin"))
    sim.step(3)
    again = stokesrods.Simulation(small)
    again.load_checkpoint(str(tmp_path / "c.bin"))
    assert again.time == pytest.approx(0.06) and again.steps == 3
    again.step(3)
    # Exact resume (io/checkpoint.h): the same numbers as the run that went on.
    np.testing.assert_array_equal(again.positions(1), sim.positions(1))
    np.testing.assert_array_equal(again.velocities(2), sim.velocities(2))
    with pytest.raises(OSError):
        again.load_checkpoint(str(tmp_path / "missing.bin"))
    with pytest.raises(OSError, match="run.time_step"):
        stokesrods.Simulation(small, overrides={"run.time_step": 0.01}).load_checkpoint(
            str(tmp_path / "c.bin"))


def test_checkpoint_keeps_the_controls_set_between_steps(tmp_path, small):
    # A controller changed omega and the loads; a fresh Simulation of the same configuration that
    # loads the checkpoint continues with those controls, digit for digit, not the configured ones.
    force = [0.0, 2e-4, 0.0]
    sim = stokesrods.Simulation(small)
    sim.step(2)
    sim.set_omega(1, 3.0)
    sim.set_loads(2, {20: force, 7: [1e-4, 0.0, 0.0]})
    sim.step(1)
    sim.save_checkpoint(str(tmp_path / "c.bin"))
    sim.step(3)
    again = stokesrods.Simulation(small)
    assert again.omega(1) != 3.0 and again.loads(2) == {}
    again.load_checkpoint(str(tmp_path / "c.bin"))
    assert again.omega(1) == 3.0 and again.omega(2) == sim.omega(2)
    assert sorted(again.loads(2)) == [7, 20] and again.loads(1) == {}
    np.testing.assert_array_equal(again.loads(2)[20], force)
    again.step(3)
    np.testing.assert_array_equal(again.positions(1), sim.positions(1))
    np.testing.assert_array_equal(again.positions(2), sim.positions(2))
    # Without the controls (as before checkpoint version 3) the continuation differs.
    forgetful = stokesrods.Simulation(small)
    forgetful.load_checkpoint(str(tmp_path / "c.bin"))
    forgetful.set_omega(1, stokesrods.Simulation(small).omega(1))
    forgetful.set_loads(2, {})
    forgetful.step(3)
    assert np.abs(forgetful.positions(2) - sim.positions(2)).max() > 1e-7

