#!/usr/bin/env python3
"""verti's side of the controlled soil runs against Chrono (docs/src/results/chrono.md): the
HMMWV driven straight by the reference's driver law with `soil_probe` (crates/verti-sim/
examples), beside the numbers Chrono 9.0.1 gave for the same runs with the harness of
../shared/chrono-anchor (recorded below; how they were made is in the page).

    python3 scripts/soil_probe_tables.py      # three tables: flat soil, climbing, across a slope
    SOIL_PROBE=/tmp/soil_probe python3 scripts/soil_probe_tables.py   # another build's probe

1. Flat soil at 3 m/s after the reference's drop start, averages over 10-30 s: wheel torque,
   the deepest node under the front and rear wheels, wheel slip, and the drop of the centre of
   mass below where it runs on rigid ground.
2. Climbing a ramp whose slope grows by 0.8/90 per metre from x = -35 m: the slope at which the
   speed first falls below 2 m/s, and at which the mean slip 1 - v/(w r) of the four wheels
   first exceeds 20 % and 50 %.
3. Along a 15 deg side slope at 3 m/s: the mean roll over 10-30 s.
4. Out of soil (x < 0) onto rigid ground (x > 0, friction 0.8) after the drop start: the speed
   in the soil, the slowest speed and largest nose-up pitch as the front axle crosses (centre
   of mass 4.7 m to 0.7 m short of the edge) and as the rear axle does (0.6 m to 4.6 m past
   it), and the highest point of the centre of mass over its rest height on the rigid side.
"""

import csv
import io
import math
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SOILS = ("snow", "mud", "sand")
RADIUS = 0.467  # the HMMWV's rigid tyre

# Chrono 9.0.1, the reference's HMMWV and SCM set-up (bulldozing on), from the harness runs
# described in chrono.md: wheel torque at 1 ms; drop of the centre of mass at 3 m/s; slopes.
CHRONO_FLAT = {
    "snow": ("4850", "0.11 / 0.17", "6.5 %", "0.12"),
    "mud": ("2125", "0.048 / 0.050", "1.5 %", "0.05"),
    "sand": ("977", "0.012 / 0.010", "0.6 %", ""),
}
CHRONO_RAMP = {"snow": (24.3, 13.3, 21.4), "mud": (29.6, 21.0, 27.3), "sand": (31.9, 22.2, 29.5)}
CHRONO_ROLL = {"snow": 15.7, "mud": 15.3, "sand": 15.2}


def probe(*args, env=None):
    """Rows of one soil_probe run (every 0.1 s)."""
    import os

    e = dict(os.environ, VERTI_PROBE_EVERY="20", **(env or {}))
    # SOIL_PROBE=PATH: a soil_probe binary built elsewhere (e.g. before a change)
    cmd = [os.environ["SOIL_PROBE"]] if os.environ.get("SOIL_PROBE") else [
        "cargo", "run", "-q", "--release", "--locked", "-p", "verti-sim", "--example", "soil_probe", "--"]
    out = subprocess.run(
        [*cmd, *args],
        cwd=ROOT, env=e, capture_output=True, text=True, check=True,
    ).stdout
    return [{k: float(v) for k, v in r.items()} for r in csv.DictReader(io.StringIO(out))]


def pct(x):
    """A share as "1.2 %" (no "-0.0 %")."""
    return f"{0.0 if abs(x) < 5e-4 else 100 * x:.1f} %"


def mean(rows, key):
    return sum(r[key] for r in rows) / len(rows)


def slip(r):
    spins = [r[f"omega_{w}"] for w in ("fl", "fr", "rl", "rr")]
    return sum(1 - r["v"] / (w * RADIUS) if w * RADIUS > 1e-6 else 0.0 for w in spins) / 4


def flat():
    rest = mean([r for r in probe("side", "rigid", "0", "30", env={"VERTI_PROBE_DROP": "1"}) if 10 <= r["t"] <= 30], "z")
    print("| soil | wheel torque, Chrono | verti | sinkage front / rear, Chrono | verti | wheel slip, Chrono / verti | drop of the centre of mass, Chrono | verti |")
    print("|---|---:|---:|---|---|---|---:|---:|")
    for soil in SOILS:
        rows = [r for r in probe("side", soil, "0", "30", env={"VERTI_PROBE_DROP": "1"}) if 10 <= r["t"] <= 30]
        torque, sink, sl, drop = CHRONO_FLAT[soil]
        front = (mean(rows, "sinkage_fl") + mean(rows, "sinkage_fr")) / 2
        rear = (mean(rows, "sinkage_rl") + mean(rows, "sinkage_rr")) / 2
        print(
            f"| {soil} | {torque} N m | {mean(rows, 'wheel_torque'):.0f} N m | {sink} m | {front:.3f} / {rear:.3f} m "
            f"| {sl} / {pct(sum(slip(r) for r in rows) / len(rows))} | {drop + ' m' if drop else ''} "
            f"| {rest - mean(rows, 'z'):.3f} m |"
        )


def ramp():
    print()
    print("| soil | speed below 2 m/s, Chrono | verti | slip over 20 % / 50 %, Chrono | verti |")
    print("|---|---:|---:|---|---|")
    c = 0.8 / 90
    for soil in SOILS:
        rows = probe("ramp", soil, "0", "60")
        angle = lambda r: math.degrees(math.atan(max(0.0, c * (r["x"] + 35))))
        climbing = [r for r in rows if r["x"] > -35 and r["t"] > 5]
        slow = next((angle(r) for r in climbing if r["v"] < 2.0), float("nan"))
        onset = [next((angle(r) for r in climbing if slip(r) > s), float("nan")) for s in (0.2, 0.5)]
        cs, c20, c50 = CHRONO_RAMP[soil]
        print(f"| {soil} | {cs}° | {slow:.1f}° | {c20}° / {c50}° | {onset[0]:.1f}° / {onset[1]:.1f}° |")


def side():
    print()
    print("| soil | mean roll at 15°, Chrono | verti |")
    print("|---|---:|---:|")
    for soil in SOILS:
        rows = [r for r in probe("side", soil, "15", "30") if 10 <= r["t"] <= 30]
        print(f"| {soil} | {CHRONO_ROLL[soil]}° | {abs(mean(rows, 'roll')):.1f}° |")


def edge():
    print()
    print("| run | speed before | slowest, front axle crossing | nose-up pitch | slowest, rear axle crossing | pitch | overshoot over rest height |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for soil, speed in (("snow", "3"), ("snow", "1.5"), ("mud", "3")):
        rows = probe("edge", soil, "0", "75", env={"VERTI_PROBE_DROP": "1", "VERTI_PROBE_SPEED": speed})
        before = [r["v"] for r in rows if -8 < r["x"] < -4]
        front = [r for r in rows if -4.7 <= r["x"] <= -0.7]
        rear = [r for r in rows if 0.6 <= r["x"] <= 4.6]
        rest = [r["z"] for r in rows if r["x"] > 8]
        over = max(r["z"] for r in rows if -3 < r["x"] < 6) - sum(rest) / len(rest)
        print(
            f"| verti, {soil}, {speed} m/s | {sum(before) / len(before):.2f} | {min(r['v'] for r in front):.2f} "
            f"| {max(-r['pitch'] for r in front):.1f}° | {min(r['v'] for r in rear):.2f} "
            f"| {max(0.0, max(r['pitch'] for r in rear)):.1f}° | {max(0.0, over):.2f} m |"
        )


if __name__ == "__main__":
    flat()
    ramp()
    side()
    edge()
