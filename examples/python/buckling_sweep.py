#!/usr/bin/python3
"""A buckling sweep from Python (paper Fig. 5): one rotating helix at several ω̄, its normalized
length l̄ and how far its tip leaves the axis at the end.

    PYTHONPATH=build/release/python /usr/bin/python3 examples/python/buckling_sweep.py [--quick]

Below the buckling rate ω̄_b the helix stays straight and stretches slightly (l̄ ≳ 1); above it
the helix buckles and its tip swings off the axis. scripts/studies/buckling.py bisects ω̄_b.
"""
import argparse
import os

import stokesrods

HERE = os.path.dirname(os.path.abspath(__file__))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="two short runs, for a check")
    parser.add_argument("--omega-bar", type=float, nargs="+", default=[320, 533, 800, 1067])
    parser.add_argument("--t-bar-end", type=float, default=0.5)
    args = parser.parse_args()
    rates = [320, 1067] if args.quick else args.omega_bar
    t_bar_end = 0.02 if args.quick else args.t_bar_end
    print(f"{'omega_bar':>10} {'l_bar':>8} {'tip off axis [mm]':>18} status")
    for w in rates:
        result = stokesrods.run(
            os.path.join(HERE, "..", "helix.toml"),
            overrides={"rods.omega_bar": w, "run.t_bar_end": t_bar_end, "run.integrator": "bdf2",
                       "run.time_step": 0.02, "run.frames": False},
            output=f"out/buckling_py/omega_bar_{w:g}", check=False)
        final = result.summary["final"]
        print(f"{w:10g} {final['rod1_length_bar']:8.4f} "
              f"{1000 * final['rod1_tip_axis_distance']:18.2f} {result.status}")


if __name__ == "__main__":
    main()
