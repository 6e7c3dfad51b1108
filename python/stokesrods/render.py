"""Pictures and a video of a finished run (`stokesrods render RUN_DIR`).

Writes into RUN_DIR/render/: views.png (front x-z and side y-z views at chosen times, as the
paper's Fig. 1: every rod drawn as a tube of its own radius), run.mp4 (both views, t and t̄ on
every frame; ffmpeg) and flow.png (the flow on the planes written by [flow_field], Fig. 6b).

usage: python3 -m stokesrods.render RUN_DIR [--times T ...] [--color rod|contact_force|...]
                                    [--no-video] [--fps N] [--max-frames N] [--output-dir DIR]
Exit codes as the command line's: 2 bad input (no such run, unknown field), 4 input/output.
"""
import argparse
import glob
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np

from .results import frame_index, read_frame, read_timeseries
from .tubes import draw_rods, segment_values, view_limits

VIEWS = [("front", 0, "x [cm]"), ("side", 1, "y [cm]")]  # (name, horizontal axis, label)


def fail(code, message):
    print(f"error: {message}", file=sys.stderr)
    sys.exit(code)


def load_run(run_dir):
    import json
    if not os.path.isdir(run_dir):
        fail(2, f"{run_dir}: not a directory")
    try:
        with open(os.path.join(run_dir, "summary.json")) as f:
            summary = json.load(f)
    except OSError as e:
        fail(2, f"{run_dir}: not a finished run ({e.strerror}: summary.json)")
    index = frame_index(run_dir)
    if not index:
        fail(2, f"{run_dir}: no ParaView frames (rods.pvd); run with run.frames = true")
    return summary, index


def radii(summary, rods):
    """The radius of every rod, from the resolved configuration."""
    configured = summary["config"]["rods"]
    return [configured[min(k, len(configured) - 1)]["radius"] for k in range(len(rods))]


def t_bar(summary, t):
    scale = summary.get("derived", {}).get("time_scale")
    return t / scale if scale else float("nan")


def views_figure(plt, frames, summary, color, field_range):
    """Front and side views (rows) at each time (columns)."""
    limits = view_limits([rods for _, rods, _ in frames])
    fig, axes = plt.subplots(2, len(frames), figsize=(2.4 * len(frames) + 0.8, 8.0), squeeze=False,
                             layout="constrained")
    mappable = None
    for column, (t, rods, data) in enumerate(frames):
        for row, (name, axis, label) in enumerate(VIEWS):
            ax = axes[row][column]
            mappable = draw_rods(ax, rods, radii(summary, rods), axis, data, color, field_range)
            ax.set_xlim(*limits[axis])
            ax.set_ylim(*limits[2])
            ax.set_aspect("equal")
            ax.set_xlabel(label)
            ax.xaxis.set_major_locator(MaxNLocator(4))
            if column == 0:
                ax.set_ylabel("z [cm]")
            ax.set_title(f"{name}, t = {t:.3g} s\n$\\bar{{t}}$ = {t_bar(summary, t):.3g}", fontsize=9)
            ax.grid(alpha=0.25)
    add_colorbar(fig, mappable, axes, color)
    return fig


def add_colorbar(fig, mappable, axes, color):
    if mappable is not None:
        fig.colorbar(mappable, ax=axes, shrink=0.5,
                     label=f"|{color}| [N] (a segment: the mean of its two nodes)")


def field_range(frames, color):
    """(0, largest value a segment shows) over the frames (t, rods, data): the range of the colours
    drawn (tubes.segment_values), so the top of the colour bar is a colour on the picture."""
    if color == "rod":
        return None
    values = [np.concatenate(segment_values(r, d, color)) for _, r, d in frames if color in d]
    if not values:
        return None
    top = max(float(v.max()) for v in values)
    return (0.0, top if top > 0 else 1.0)


def write_views(plt, run_dir, summary, index, times, color, out):
    stamps = np.array([t for t, _ in index])
    if not times:
        end = stamps[-1]
        times = [stamps[0]] + [end * k / 3 for k in (1, 2, 3)] if end > 0 else [stamps[0]]
    chosen = sorted({int(np.argmin(np.abs(stamps - t))) for t in times})
    frames = [(index[i][0],) + read_frame(index[i][1]) for i in chosen]
    check_field(frames[0][2], color)
    fig = views_figure(plt, frames, summary, color, field_range(frames, color))
    fig.savefig(out, dpi=170)
    plt.close(fig)
    return out


def check_field(data, color):
    if color != "rod" and color not in data:
        names = ", ".join(["rod"] + [n for n, v in data.items() if np.ndim(v) == 2])
        fail(2, f"--color {color}: no such point data in the frames (known: {names})")


def write_video(plt, run_dir, summary, index, color, fps, max_frames, out):
    if shutil.which("ffmpeg") is None:
        fail(4, "ffmpeg not found (Debian package ffmpeg; scripts/install_deps.sh installs it)")
    stride = max(1, int(np.ceil(len(index) / max_frames)))
    chosen = index[::stride]
    if chosen[-1] != index[-1]:
        chosen.append(index[-1])
    all_rods = [read_frame(p) for _, p in chosen]
    limits = view_limits([rods for rods, _ in all_rods])
    frange = field_range([(t, r, d) for (t, _), (r, d) in zip(chosen, all_rods)], color)
    with tempfile.TemporaryDirectory() as tmp:
        for k, ((t, _), (rods, data)) in enumerate(zip(chosen, all_rods)):
            fig, axes = plt.subplots(1, 2, figsize=(8.0, 7.2), layout="constrained")
            for ax, (name, axis, label) in zip(axes, VIEWS):
                mappable = draw_rods(ax, rods, radii(summary, rods), axis, data, color, frange)
                ax.set_xlim(*limits[axis])
                ax.set_ylim(*limits[2])
                ax.set_aspect("equal")
                ax.set_xlabel(label)
                ax.xaxis.set_major_locator(MaxNLocator(4))
                ax.set_ylabel("z [cm]")
                ax.set_title(name)
                ax.grid(alpha=0.25)
            add_colorbar(fig, mappable, axes, color)
            fig.suptitle(f"t = {t:7.2f} s    $\\bar{{t}}$ = {t_bar(summary, t):.4f}")
            fig.savefig(os.path.join(tmp, f"f{k:05d}.png"), dpi=100)
            plt.close(fig)
        cmd = ["ffmpeg", "-y", "-loglevel", "error", "-framerate", str(fps), "-i",
               os.path.join(tmp, "f%05d.png"), "-vf", "scale=trunc(iw/2)*2:trunc(ih/2)*2",
               "-c:v", "libx264", "-pix_fmt", "yuv420p", out]
        done = subprocess.run(cmd, capture_output=True, text=True)
        if done.returncode != 0:
            fail(4, f"{out}: ffmpeg failed: {done.stderr.strip()}")
    return out


def write_flow(plt, run_dir, summary, index, out):
    """The flow on each written plane (Fig. 6b): speed in colour, in-plane streamlines, the rods'
    centre lines projected. None if the run wrote no planes."""
    files = sorted(glob.glob(os.path.join(run_dir, "flow", "flow_*.csv")))
    if not files:
        return None
    plane = summary["config"]["flow_field"]
    times = sorted(plane["times"])
    nu, nv = plane["resolution"]
    origin, u_edge, v_edge = (np.array(plane[k]) for k in ("origin", "u", "v"))
    eu, ev = u_edge / np.linalg.norm(u_edge), v_edge / np.linalg.norm(v_edge)
    stamps = np.array([t for t, _ in index])
    fig, axes = plt.subplots(1, len(files), figsize=(3.2 * len(files), 7.0), squeeze=False)
    for k, path in enumerate(files):
        d = read_timeseries(path)
        p = np.stack([d["x"], d["y"], d["z"]], axis=1) - origin
        w = np.stack([d["ux"], d["uy"], d["uz"]], axis=1)
        a, b = (p @ eu).reshape(nv, nu), (p @ ev).reshape(nv, nu)
        wa, wb = (w @ eu).reshape(nv, nu), (w @ ev).reshape(nv, nu)
        speed = np.linalg.norm(w, axis=1).reshape(nv, nu)
        ax = axes[0][k]
        mesh = ax.pcolormesh(100 * a, 100 * b, 1000 * speed, shading="gouraud", cmap="viridis")
        ax.streamplot(100 * a[0, :], 100 * b[:, 0], wa, wb, color="w", density=1.0,
                      linewidth=0.6, arrowsize=0.6)
        t = times[k] if k < len(times) else float("nan")
        rods, _ = read_frame(index[int(np.argmin(np.abs(stamps - t)))][1])
        for x in rods:
            q = x - origin
            ax.plot(100 * q @ eu, 100 * q @ ev, "-", color="tab:red", lw=1.5, alpha=0.8)
        ax.set_aspect("equal")
        ax.set_title(f"t = {t:g} s, $\\bar{{t}}$ = {t_bar(summary, t):.3g}", fontsize=9)
        ax.set_xlabel("along u [cm]")
        if k == 0:
            ax.set_ylabel("along v [cm]")
        fig.colorbar(mesh, ax=ax, shrink=0.6, label="|u| [mm/s]")
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(prog="stokesrods render", description=__doc__.splitlines()[0])
    parser.add_argument("run_dir")
    parser.add_argument("--times", type=float, nargs="+", default=None,
                        help="times of the views [s] (default: start, 1/3, 2/3, end)")
    parser.add_argument("--color", default="rod",
                        help="rod (one colour per rod) or a point-data field of the frames "
                             "(contact_force, hydrodynamic_force): its magnitude")
    parser.add_argument("--no-video", action="store_true", help="pictures only")
    parser.add_argument("--fps", type=int, default=20)
    parser.add_argument("--max-frames", type=int, default=300,
                        help="longest video in frames (every k-th frame beyond)")
    parser.add_argument("--output-dir", default=None, help="default: RUN_DIR/render")
    args = parser.parse_args(argv)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    global MaxNLocator
    from matplotlib.ticker import MaxNLocator
    summary, index = load_run(args.run_dir)
    out_dir = args.output_dir or os.path.join(args.run_dir, "render")
    try:
        os.makedirs(out_dir, exist_ok=True)
    except OSError as e:
        fail(4, f"{out_dir}: cannot create: {e.strerror}")
    written = [write_views(plt, args.run_dir, summary, index, args.times, args.color,
                           os.path.join(out_dir, "views.png"))]
    written.append(write_flow(plt, args.run_dir, summary, index, os.path.join(out_dir, "flow.png")))
    if not args.no_video:
        written.append(write_video(plt, args.run_dir, summary, index, args.color, args.fps,
                                   args.max_frames, os.path.join(out_dir, "run.mp4")))
    for path in written:
        if path:
            print(f"wrote {path}")


if __name__ == "__main__":
    main()
