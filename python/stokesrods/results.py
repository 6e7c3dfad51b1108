"""Reading a run's outputs (SPEC "Outputs") with NumPy only: timeseries.csv, summary.json and the
ParaView frames (rods.pvd + frames/*.vtp, ASCII or binary)."""
import base64
import json
import os
import xml.etree.ElementTree as ET

import numpy as np


def read_timeseries(path):
    """{column: 1-D array} of a timeseries.csv, in the file's column order."""
    with open(path) as f:
        columns = f.readline().strip().split(",")
    values = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    if values.size == 0:
        values = np.zeros((0, len(columns)))
    return {name: values[:, k] for k, name in enumerate(columns)}


def frame_index(run_dir):
    """[(time, path)] of the frames listed in rods.pvd, in time order ([] if none)."""
    pvd = os.path.join(run_dir, "rods.pvd")
    if not os.path.exists(pvd):
        return []
    tree = ET.parse(pvd)
    frames = [(float(d.get("timestep")), os.path.join(run_dir, d.get("file")))
              for d in tree.iter("DataSet")]
    return sorted(frames)


_TYPES = {"Float64": "<f8", "Float32": "<f4", "Int32": "<i4", "Int64": "<i8", "UInt8": "u1",
          "UInt32": "<u4", "UInt64": "<u8"}


def _array(node, appended):
    """The values of a VTK DataArray: ascii, binary (base64) or appended raw."""
    dtype = np.dtype(_TYPES[node.get("type")])
    fmt = node.get("format", "ascii")
    if fmt == "ascii":
        return np.array((node.text or "").split(), dtype=dtype)
    if fmt == "binary":
        raw = base64.b64decode("".join((node.text or "").split()))
        size = int(np.frombuffer(raw[:8], "<u8")[0])  # header_type UInt64
        return np.frombuffer(raw[8:8 + size], dtype=dtype)
    offset = int(node.get("offset"))
    size = int(np.frombuffer(appended[offset:offset + 8], "<u8")[0])
    return np.frombuffer(appended[offset + 8:offset + 8 + size], dtype=dtype)


def read_frame(path):
    """Node positions per rod ([N_k × 3 arrays]) and point data {name: (M × C) or (M,) array}."""
    with open(path, "rb") as f:
        content = f.read()
    appended = b""
    marker = content.find(b"<AppendedData")
    if marker >= 0:  # raw bytes after '_' up to the closing tag
        start = content.index(b"_", content.index(b">", marker)) + 1
        end = content.rindex(b"</AppendedData>")
        appended = content[start:end]
        content = content[:marker] + b"</VTKFile>"
    root = ET.fromstring(content.decode("latin-1"))
    piece = root.find("PolyData/Piece")
    points = _array(piece.find("Points/DataArray"), appended).astype(float).reshape(-1, 3)
    offsets = None
    for array in piece.find("Lines").iter("DataArray"):
        if array.get("Name") == "offsets":
            offsets = _array(array, appended).astype(int)
    starts = np.concatenate([[0], offsets[:-1]])
    rods = [points[a:b] for a, b in zip(starts, offsets)]
    data = {}
    for array in piece.find("PointData").iter("DataArray"):
        values = _array(array, appended)
        components = int(array.get("NumberOfComponents", "1"))
        data[array.get("Name")] = values.reshape(-1, components) if components > 1 else values
    return rods, data


def nearest_frames(run_dir, times):
    """The (time, path) of the frame nearest to each requested time."""
    frames = frame_index(run_dir)
    stamps = np.array([t for t, _ in frames])
    return [frames[int(np.argmin(np.abs(stamps - t)))] for t in times]


class Result:
    """The outputs of one run directory.

    timeseries: {column: array} (timeseries.csv); summary: summary.json as a dict; status;
    frame_times: the times of the ParaView frames; positions: per frame, a list of N_k × 3
    arrays (one per rod); point_data: per frame, {name: M × 3 array} over all nodes (e.g.
    "hydrodynamic_force", "contact_force"); forces(name): per frame, a list per rod.
    Frames are read on first use.
    """

    def __init__(self, run_dir):
        self.run_dir = os.fspath(run_dir)
        self.timeseries = read_timeseries(os.path.join(self.run_dir, "timeseries.csv"))
        with open(os.path.join(self.run_dir, "summary.json")) as f:
            self.summary = json.load(f)
        self._frames = None

    @property
    def status(self):
        return self.summary["status"]

    def _load_frames(self):
        if self._frames is None:
            index = frame_index(self.run_dir)
            self._frames = (np.array([t for t, _ in index]), [read_frame(p) for _, p in index])
        return self._frames

    @property
    def frame_times(self):
        return self._load_frames()[0]

    @property
    def positions(self):
        return [rods for rods, _ in self._load_frames()[1]]

    @property
    def point_data(self):
        return [data for _, data in self._load_frames()[1]]

    def forces(self, name="hydrodynamic_force"):
        """Per frame, the per-node force `name` split by rod (N_k × 3 arrays)."""
        out = []
        for rods, data in self._load_frames()[1]:
            ends = np.cumsum([len(x) for x in rods])
            out.append(np.split(data[name], ends[:-1]))
        return out

    def __repr__(self):
        return f"<stokesrods.Result {self.run_dir!r} status={self.status!r}>"


def load(run_dir):
    """The Result of a finished (or interrupted) run directory."""
    return Result(run_dir)
