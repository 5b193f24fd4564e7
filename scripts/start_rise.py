#!/usr/bin/env python3
"""Counts the benchmark's settled starts that begin inside the ground.

A settled start (the default of `verti eval`) sets the vehicle at rest on the terrain; a start
that leaves part of the vehicle inside rigid ground is thrown up by the stiff contact in its
first steps instead. For each vehicle, every start of verti-100 (at the vehicle's scale) is
stepped for 30 ms with the brake on, and a start counts as thrown when the reference point
moved up faster than 0.3 m/s (times the square root of the scale) in that time: a stiff
contact throws a vehicle within milliseconds, before one set down a little above the ground
has landed.
Prints one line per vehicle and, with --list, the starts.

    source python/.venv/bin/activate
    python3 scripts/start_rise.py [--list] [VEHICLE ...]
"""

import argparse
import re
from pathlib import Path

import verti

VEHICLES = Path(__file__).resolve().parent.parent / "crates/verti-sim/vehicles"


def vehicle_scale(name):
    """The scale a built-in vehicle drives at: its file's `scale`."""
    text = (VEHICLES / f"{name}.yaml").read_text()
    return float(re.search(r"^scale:\s*(\S+)", text, re.M).group(1))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("vehicles", nargs="*", help="default: every built-in vehicle")
    parser.add_argument("--list", action="store_true", help="print each thrown start")
    parser.add_argument("--threshold", type=float, default=0.3, help="upward speed in m/s at full scale")
    args = parser.parse_args()
    worlds_by_scale = {}
    for vehicle in args.vehicles or verti.vehicles():
        scale = vehicle_scale(vehicle)
        if scale not in worlds_by_scale:
            worlds_by_scale[scale] = verti.load_worlds("verti-100", scale=None if scale == 1.0 else scale)
        rose, worst = [], 0.0
        for world in worlds_by_scale[scale]:
            for task in world.tasks:
                sim = verti.Sim(world, vehicle, start=task["pair"])
                up = 0.0
                for _ in range(3):
                    sim.step(0.0, 1.0, 0.0)
                    up = max(up, sim.state.to_dict()["vz"])
                worst = max(worst, up)
                if up > args.threshold * scale**0.5:
                    rose.append((task["task"], up))
        print(f"{vehicle}: {len(rose)} of 1000 starts thrown up faster than "
              f"{args.threshold * scale**0.5:.2f} m/s (fastest {worst:.2f} m/s)", flush=True)
        if args.list:
            for task, up in rose:
                print(f"  task {task}: {up:.2f} m/s")


if __name__ == "__main__":
    main()
