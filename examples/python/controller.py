#!/usr/bin/python3
"""A rod driven by a controller: the motor rate of one helix is adjusted between steps so that its
thrust (the clamp's reaction force along z, paper eq. 25) reaches a target.

    PYTHONPATH=build/release/python /usr/bin/python3 examples/python/controller.py [--quick]

The thrust of a slowly turning helix is about proportional to its rate, F ≈ c ω. The controller
measures c once at the starting rate, then every control period (10 steps) moves the rate by
half the remaining error: ω ← ω + (F_target − F) / (2c), through Simulation.set_omega. The table
shows the thrust settling on the target (twice the starting thrust by default).
"""
import argparse
import os

import stokesrods

HERE = os.path.dirname(os.path.abspath(__file__))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a few control periods, for a check")
    parser.add_argument("--target-ratio", type=float, default=2.0,
                        help="target thrust over the thrust at the starting rate")
    args = parser.parse_args()
    sim = stokesrods.Simulation(os.path.join(HERE, "..", "helix.toml"),
                                overrides={"run.time_step": 0.02, "run.integrator": "bdf2",
                                           "rods.omega_bar": 100})
    sim.step(50)  # settle at the starting rate
    thrust = sim.clamp_load(1)["force"][2]
    c = thrust / sim.omega(1)  # [N per rad/s]
    target = args.target_ratio * thrust
    print(f"starting rate {sim.omega(1):.4f} rad/s, thrust {thrust:.4e} N; target {target:.4e} N")
    print(f"{'t [s]':>7} {'omega [rad/s]':>14} {'thrust [N]':>12} {'error':>8}")
    for k in range(4 if args.quick else 40):
        sim.set_omega(1, sim.omega(1) + 0.5 * (target - thrust) / c)
        sim.step(10)
        thrust = sim.clamp_load(1)["force"][2]
        if args.quick or k % 4 == 3:
            print(f"{sim.time:7.2f} {sim.omega(1):14.4f} {thrust:12.4e} {thrust / target - 1:8.1%}")


if __name__ == "__main__":
    main()
