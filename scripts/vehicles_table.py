"""The nine-vehicle tables of the documentation (docs/src/reference/engine.md): PID on all 1000
tasks of verti-100 and MPPI on every 10th task, for every built-in vehicle at its scale.

    bash scripts/benchmarks.sh unpack && python3 scripts/vehicles_table.py

Reads the committed runs: `benchmarks/verti-100/{pid,mppi}` for the HMMWV (Verti-Bench's
vehicle, the benchmark's own runs) and `benchmarks/vehicles/{pid,mppi}-V[-sub100]` for the
others (the artcar drives verti-100 at 1/6 scale, the verti4 at 1/10). Prints two tables, one
per system: success, rollover and stuck (%) overall, and success per elevation level. A run
with fewer results than its table's task count says how many it has.
"""

from pathlib import Path

from run_rows import rows, share, success_by_level

VEHICLES = [
    ("hmmwv", "1", "4 wheels, Ackermann (rigid tyres)"),
    ("hmmwv-handling", "1", "4 wheels, Ackermann (handling tyres)"),
    ("uaz", "1", "4 wheels, leaf-spring solid axles, toe bar"),
    ("gator", "1", "4 wheels, single wishbone, rack and pinion"),
    ("sedan", "1", "4 wheels, double wishbone / multilink, rack and pinion"),
    ("truck6", "1", "6 wheels, three-link solid axles, rotary arm and bellcrank"),
    ("truck8", "1", "8 wheels, three-link solid axles, a rotary arm and bellcrank on each of two steered axles"),
    ("m113", "1", "2 tracks, skid steering (steer unit)"),
    ("artcar", "1/6", "4 wheels, double wishbone, Pitman arm"),
    ("verti4", "1/10", "4 wheels, independent wheels, Ackermann"),
]
SUBSET = set(range(1, 1001, 10))


def run_dir(root, system, vehicle, sub100):
    if vehicle == "hmmwv":
        return root / "verti-100" / system
    return root / "vehicles" / (f"{system}-{vehicle}" + ("-sub100" if sub100 else ""))


def table(root, system, sub100):
    tasks = SUBSET if sub100 else None
    expected = len(SUBSET) if sub100 else 1000
    lines = [
        "| vehicle | scale | chassis, suspension, steering | success | rollover | stuck | success low / mid / high |",
        "|---|---|---|---:|---:|---:|---|",
    ]
    for name, scale, what in VEHICLES:
        rs = rows(run_dir(root, system, name, sub100), tasks)
        if not rs:
            lines.append(f"| `{name}` | {scale} | {what} | — | — | — | not run |")
            continue
        n = len(rs)
        levels = success_by_level(rs)
        note = "" if n == expected else f" ({n} of {expected} tasks)"
        lines.append(
            f"| `{name}` | {scale} | {what} | {share(rs, 'success')}{note} | "
            f"{share(rs, 'rollover')} | {share(rs, 'stuck')} | {' / '.join(levels)} |"
        )
    return "\n".join(lines) + "\n"


def main():
    root = Path(__file__).resolve().parent.parent / "benchmarks"
    print(table(root, "pid", sub100=False))
    print(table(root, "mppi", sub100=True))


if __name__ == "__main__":
    main()
