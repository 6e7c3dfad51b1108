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


def read_vtp_strictly(path):
    """A reader of VTK XML PolyData written from the file format's description (VTK User's Guide,
    "XML File Formats"), independent of stokesrods.results: ascii, inline base64 and appended raw
    arrays, header_type UInt64, little-endian. Checks what a VTK reader relies on: array lengths
    against NumberOfPoints and NumberOfComponents, and appended blocks that tile the data exactly
    in offset order. Returns {"Points/points": array, "PointData/NAME": array, ...}, each M × C."""
    import base64
    import xml.etree.ElementTree as ET
    raw = open(path, "rb").read()
    block = b""
    start = raw.find(b"<AppendedData")
    if start >= 0:
        tag_end = raw.index(b">", start) + 1
        assert b'encoding="raw"' in raw[start:tag_end]
        underscore = raw.index(b"_", tag_end)
        assert raw[tag_end:underscore].strip() == b""  # only whitespace before the '_' marker
        close = raw.rindex(b"</AppendedData>")
        block = raw[underscore + 1:close].rstrip(b"\n")
        head = raw[:start] + b"</VTKFile>"
    else:
        head = raw
    root = ET.fromstring(head)
    assert root.get("type") == "PolyData" and root.get("byte_order") == "LittleEndian"
    assert root.get("header_type") == "UInt64"
    piece = root.find("PolyData/Piece")
    points = int(piece.get("NumberOfPoints"))
    dtypes = {"Float64": "<f8", "Int32": "<i4"}
    arrays, used = {}, []
    for parent in ("Points", "Lines", "PointData"):
        for node in piece.find(parent).findall("DataArray"):
            dtype = np.dtype(dtypes[node.get("type")])
            components = int(node.get("NumberOfComponents", "1"))
            form = node.get("format")
            if form == "ascii":
                values = np.array(node.text.split(), dtype=dtype)
            else:
                if form == "binary":
                    data = base64.b64decode(node.text.strip(), validate=True)
                    offset = 0
                else:
                    assert form == "appended" and not (node.text or "").strip()
                    data, offset = block, int(node.get("offset"))
                count = int.from_bytes(data[offset:offset + 8], "little")
                assert count % dtype.itemsize == 0 and offset + 8 + count <= len(data)
                values = np.frombuffer(data[offset + 8:offset + 8 + count], dtype=dtype)
                if form == "binary":
                    assert 8 + count == len(data)
                else:
                    used.append((offset, offset + 8 + count))
            if parent != "Lines":
                assert values.size == points * components, node.get("Name")
            arrays[f"{parent}/{node.get('Name')}"] = values.reshape(-1, components)
    if used:  # the appended arrays, in offset order, cover the block without gaps or overlaps
        used.sort()
        assert used[0][0] == 0 and used[-1][1] == len(block)
        assert all(a[1] == b[0] for a, b in zip(used, used[1:]))
    return arrays


def test_appended_frames_are_exact_smaller_and_read_by_a_strict_reader(tmp_path, small):
    runs = {f: stokesrods.run(small, overrides={"run.frames_format": f}, output=tmp_path / f)
            for f in ("ascii", "binary", "appended")}
    frames = sorted((tmp_path / "ascii" / "frames").glob("rods_*.vtp"))
    assert len(frames) == 4
    for frame in frames:
        text, base64, appended = (read_vtp_strictly(tmp_path / f / "frames" / frame.name)
                                  for f in ("ascii", "binary", "appended"))
        assert b"AppendedData" in open(tmp_path / "appended" / "frames" / frame.name, "rb").read()
        assert sorted(appended) == sorted(text) == sorted(base64)
        for name, values in appended.items():
            np.testing.assert_array_equal(values, base64[name])  # both exact: bit for bit
            # ASCII keeps 10 significant digits of points and radius, 8 of the other doubles.
            digits = 10 if name in ("Points/points", "PointData/radius") else 8
            scale = np.abs(values).max() if values.size else 1.0
            np.testing.assert_allclose(text[name], values, rtol=0,
                                       atol=0.6 * 10.0 ** (1 - digits) * scale)
        # The package's own reader agrees.
        rods, data = read_frame(str(tmp_path / "appended" / "frames" / frame.name))
        np.testing.assert_array_equal(np.vstack(rods), appended["Points/points"])
    # Exact: the last frame's tip equals the timeseries' 12 significant digits.
    tip = read_vtp_strictly(tmp_path / "appended" / "frames" / frames[-1].name)["Points/points"][20]
    ts = runs["appended"].timeseries
    np.testing.assert_allclose(tip, [ts[f"rod1_end_{a}"][-1] for a in "xyz"], rtol=5e-12, atol=0)
    size = {f: sum(p.stat().st_size for p in (tmp_path / f / "frames").glob("*.vtp"))
            for f in runs}
    assert size["appended"] < 0.8 * size["binary"] and size["appended"] < size["ascii"]
