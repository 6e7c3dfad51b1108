"""Rods drawn as tubes of their own radius in an orthographic view (Matplotlib, no 3-D axes):
each rod a ribbon of width 2 r0 along its projected centre line, shaded by depth, with a light
stripe for the round surface; pieces of all rods drawn far to near so crossings read right."""
import numpy as np

ROD_COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2",
              "#7f7f7f", "#bcbd22", "#17becf"]
CM = 100.0  # pictures in centimetres


def view_limits(frames):
    """(lo, hi) in cm of x, y and z over every rod of every frame, padded."""
    points = np.vstack([x for rods in frames for x in rods]) * CM
    lo, hi = points.min(axis=0), points.max(axis=0)
    pad = 0.08 * (hi - lo).max() + 0.3
    return [(lo[a] - pad, hi[a] + pad) for a in range(3)]


def _normals(p):
    """Unit normals of a 2-D polyline at its nodes (from the central tangents)."""
    t = np.gradient(p, axis=0)
    length = np.linalg.norm(t, axis=1)
    for i in range(len(t)):  # a node seen end on: the neighbour's tangent
        if length[i] < 1e-12:
            t[i], length[i] = (t[i - 1], length[i - 1]) if i > 0 else (np.array([1.0, 0.0]), 1.0)
    t /= length[:, None]
    return np.stack([-t[:, 1], t[:, 0]], axis=1)


def _shade(rgb, f):
    return tuple(np.clip(np.asarray(rgb[:3]) * f, 0, 1))


def segment_values(rods, data, color):
    """Per rod, what each segment shows of the per-node field `color`: the mean of the magnitudes
    at its two nodes (N − 1 values). The colour range spans these, not the node values."""
    field = np.linalg.norm(data[color], axis=1)
    values, start = [], 0
    for x in rods:
        node = field[start:start + len(x)]
        values.append(0.5 * (node[:-1] + node[1:]))
        start += len(x)
    return values


def draw_rods(ax, rods, radii, axis, data, color="rod", value_range=None):
    """Draws rods (list of N × 3 arrays [m]) seen along the horizontal axis other than `axis`
    (0: front view x-z seen from −y; 1: side view y-z seen from +x). color "rod" gives each rod
    its colour; a point-data name colours by the magnitude of that per-node field. Returns a
    ScalarMappable for a colour bar (None for "rod"). A segment shows the mean of its two nodes
    (segment_values); value_range should span those."""
    import matplotlib
    from matplotlib.collections import PolyCollection
    nearness = (lambda x: -x[:, 1]) if axis == 0 else (lambda x: x[:, 0])
    cmap = matplotlib.colormaps["plasma"]
    mappable = None
    if color != "rod":
        lo, hi = value_range or (0.0, 1.0)
        norm = matplotlib.colors.Normalize(lo, hi)
        mappable = matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap)
        shown = segment_values(rods, data, color)
    depth_all = np.concatenate([nearness(x) for x in rods])
    d_lo, d_span = depth_all.min(), max(np.ptp(depth_all), 1e-12)
    pieces = []  # (nearness, order, polygon, facecolor)
    for k, (x, r) in enumerate(zip(rods, radii)):
        p = np.stack([x[:, axis], x[:, 2]], axis=1) * CM
        n = _normals(p) * r * CM
        depth = nearness(x)
        base = matplotlib.colors.to_rgb(ROD_COLORS[k % len(ROD_COLORS)])
        for i in range(len(x) - 1):
            d = 0.5 * (depth[i] + depth[i + 1])
            f = 0.55 + 0.45 * (d - d_lo) / d_span if d_span > 1e-12 else 1.0
            rgb = base if color == "rod" else cmap(norm(shown[k][i]))
            body = [p[i] + n[i], p[i + 1] + n[i + 1], p[i + 1] - n[i + 1], p[i] - n[i]]
            stripe = [p[i] + 0.55 * n[i], p[i + 1] + 0.55 * n[i + 1], p[i + 1] + 0.2 * n[i + 1],
                      p[i] + 0.2 * n[i]]
            light = tuple(0.55 * np.asarray(_shade(rgb, f)) + 0.45)
            pieces.append((d, 2 * len(pieces), body, _shade(rgb, f)))
            pieces.append((d, 2 * len(pieces) + 1, stripe, light))
    pieces.sort(key=lambda piece: (piece[0], piece[1]))
    ax.add_collection(PolyCollection([piece[2] for piece in pieces],
                                     facecolors=[piece[3] for piece in pieces],
                                     edgecolors="none", antialiaseds=True))
    return mappable
