"""The ParaView frames: radius and material frame as point data, ASCII and binary alike."""
import numpy as np

import stokesrods
from stokesrods.results import read_frame


def test_binary_frames_equal_ascii_and_carry_radius_and_material_frame(tmp_path, small):
    small["rods"][1]["radius"] = 1.5e-3
    ascii = stokesrods.run(small, output=tmp_path / "ascii")
    binary = stokesrods.run(small, overrides={"run.frames_format": "binary"}, output=tmp_path / "bin")
    assert b'format="binary"' in open(tmp_path / "bin" / "frames" / "rods_00003.vtp", "rb").read()
    for a, b in zip(ascii.positions, binary.positions):
        for x, y in zip(a, b):
            np.testing.assert_allclose(x, y, rtol=0, atol=1e-10)  # ASCII keeps 10 digits
    sim = stokesrods.Simulation(small)
    rods, data = read_frame(str(tmp_path / "bin" / "frames" / "rods_00003.vtp"))
    # Binary frames are exact: the tip equals the timeseries' value to its 12 significant
    # digits, i.e. within half a unit of the 12th digit, 5e-12 relative (ASCII frames keep 10).
    ts = binary.timeseries
    np.testing.assert_allclose(rods[1][-1], [ts[f"rod2_end_{a}"][-1] for a in "xyz"],
                               rtol=5e-12, atol=0)
    np.testing.assert_array_equal(data["radius"], [1e-3] * 21 + [1.5e-3] * 21)
    d1, d2 = data["material_d1"], data["material_d2"]
    x = np.vstack(rods)
    tangent = np.diff(x, axis=0)
    tangent /= np.linalg.norm(tangent, axis=1)[:, None]
    for k in list(range(20)) + list(range(21, 41)):  # nodes followed by an edge of their rod
        assert abs(d1[k] @ d1[k] - 1) < 1e-7 and abs(d1[k] @ d2[k]) < 1e-7
        assert abs(d1[k] @ tangent[k]) < 1e-7 and abs(d2[k] @ tangent[k]) < 1e-7
    # The material frame turns with the imposed rotation: the clamped edge's d1 rotates about z
    # by ω t (ω̄ = 533 of rod 1 over 0.3 s).
    start, _ = read_frame(str(tmp_path / "bin" / "frames" / "rods_00000.vtp"))[1], None
    omega = sim.omega(1)
    d1_start = start["material_d1"][0]
    angle = np.arctan2(np.cross(d1_start, d1[0])[2], d1_start @ d1[0])
    assert abs(angle - omega * 0.3) < 1e-9
