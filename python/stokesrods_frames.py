"""Reading the ParaView frames of a stokesrods run (rods.pvd + frames/*.vtp) with NumPy only."""
import os
import re
import xml.etree.ElementTree as ET

import numpy as np


def frame_index(run_dir):
    """[(time, path)] of the frames listed in rods.pvd, in time order."""
    tree = ET.parse(os.path.join(run_dir, "rods.pvd"))
    frames = [(float(d.get("timestep")), os.path.join(run_dir, d.get("file")))
              for d in tree.iter("DataSet")]
    return sorted(frames)


def read_frame(path):
    """Node positions per rod ([N_k x 3 arrays]) and point data {name: (M x 3 array)}."""
    root = ET.parse(path).getroot()
    piece = root.find("PolyData/Piece")
    points = np.array(piece.find("Points/DataArray").text.split(), dtype=float).reshape(-1, 3)
    offsets = None
    for array in piece.find("Lines").iter("DataArray"):
        if array.get("Name") == "offsets":
            offsets = np.array(array.text.split(), dtype=int)
    starts = np.concatenate([[0], offsets[:-1]])
    rods = [points[a:b] for a, b in zip(starts, offsets)]
    data = {}
    for array in piece.find("PointData").iter("DataArray"):
        values = np.array(array.text.split(), dtype=float)
        components = int(array.get("NumberOfComponents", "1"))
        data[array.get("Name")] = values.reshape(-1, components) if components > 1 else values
    return rods, data


def nearest_frames(run_dir, times):
    """The (time, path) of the frame nearest to each requested time."""
    frames = frame_index(run_dir)
    stamps = np.array([t for t, _ in frames])
    return [frames[int(np.argmin(np.abs(stamps - t)))] for t in times]
