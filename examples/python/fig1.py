#!/usr/bin/python3
"""The paper's Fig. 1 from Python: two helices turning side by side bundle.

    PYTHONPATH=build/release/python /usr/bin/python3 examples/python/fig1.py [--quick]

Runs examples/fig1_bundling.toml, prints when the tips first cross (Δb = 0) and the closest
approach, and draws the pictures (out/fig1_py/render/).
"""
import argparse
import os

import numpy as np

import stokesrods
import stokesrods.render

HERE = os.path.dirname(os.path.abspath(__file__))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="5 simulated seconds, for a check")
    parser.add_argument("--output", default="out/fig1_py")
    args = parser.parse_args()
    overrides = {"run.duration": 5.0, "flow_field.times": []} if args.quick else {}
    result = stokesrods.run(os.path.join(HERE, "..", "fig1_bundling.toml"), overrides=overrides,
                            output=args.output, progress=True)
    ts = result.timeseries
    crossed = np.nonzero(ts["delta_b"] < 0)[0]
    if crossed.size:
        print(f"tips first cross at t = {ts['time'][crossed[0]]:.2f} s (t̄ = {ts['t_bar'][crossed[0]]:.3f})")
    else:
        print(f"tips have not crossed by t = {ts['time'][-1]:.2f} s")
    k = int(np.argmin(ts["min_distance"]))
    print(f"closest centre lines: {1000 * ts['min_distance'][k]:.2f} mm at t = {ts['time'][k]:.2f} s")
    stokesrods.render.main([args.output, "--no-video"] + (["--times", "0", "5"] if args.quick else []))


if __name__ == "__main__":
    main()
