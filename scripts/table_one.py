"""Table I of the ten systems beside the paper's (docs/src/results/verti-bench.md), from the
committed runs `benchmarks/SET/<system>` (after `bash scripts/benchmarks.sh unpack`).

    python3 scripts/table_one.py [SET]      # SET: verti-100 (default) or vb80

Rows: outcomes (%), success per elevation level, success and rollover on rigid worlds alone,
mean |roll| on high elevation (each trial's mean absolute roll, averaged over the trials), then
the paper's Table I. The best success among the ten is bold; † marks a system whose run predates
an engine change that calls for re-runs (the lists in benchmarks/in-progress/, scripts/stale_runs.py).
"""

import sys
from pathlib import Path

import stale_runs
from run_rows import rows, share, success_by_level

ROOT = Path(__file__).resolve().parent.parent
SYSTEMS = ["pid", "eh", "mppi", "rl", "mcl", "acl", "wmvct", "mppi6", "tal", "tnt"]
NAMES = ["PID", "EH", "MPPI", "RL", "MCL", "ACL", "WMVCT", "MPPI-6", "TAL", "TNT"]
# Verti-Bench's Table I (its HMMWV on its 1000 tasks), in SYSTEMS order
PAPER = {
    "success (%)": [48.8, 44.3, 41.2, 10.0, 41.8, 36.6, 41.5, 47.0, 58.4, 57.4],
    "rollover (%)": [14.7, 16.3, 17.9, 14.3, 16.9, 15.4, 18.9, 18.0, 17.0, 17.5],
    "stuck (%)": [36.5, 39.4, 40.9, 75.7, 41.3, 48.0, 39.6, 35.0, 24.6, 25.1],
}


def bold_max(cells):
    """Cells as text, the largest in bold."""
    values = [float(c) for c in cells]
    best = max(values)
    return [f"**{c}**" if float(c) == best else c for c in cells]


def main():
    set_name = sys.argv[1] if len(sys.argv) > 1 else "verti-100"
    runs = [rows(ROOT / "benchmarks" / set_name / s) for s in SYSTEMS]
    missing = [s for s, rs in zip(SYSTEMS, runs) if not rs]
    if missing:
        sys.exit(f"table_one: no results for {', '.join(missing)} (bash scripts/benchmarks.sh unpack)")
    # † a system whose run predates an engine change that calls for re-runs (scripts/stale_runs.py)
    stale = stale_runs.all_stale()
    names = [n + ("†" if f"benchmarks/{set_name}/{s}" in stale else "") for n, s in zip(NAMES, SYSTEMS)]
    out = ["| | " + " | ".join(names) + " |", "|---|" + "---:|" * len(NAMES)]

    def line(label, cells):
        out.append(f"| {label} | " + " | ".join(cells) + " |")

    line("Success (%)", bold_max([share(rs, "success") for rs in runs]))
    for outcome in ["rollover", "stuck", "timeout"]:
        line(f"{outcome.capitalize()} (%)", [share(rs, outcome) for rs in runs])
    line("success low / mid / high", [" / ".join(success_by_level(rs)) for rs in runs])
    rigid = [[r for r in rs if r["terrain_type"] == "rigid"] for rs in runs]
    n_rigid = len(rigid[0])
    cells = bold_max([share(rs, "success") for rs in rigid])
    line(
        f"rigid worlds only ({n_rigid}): success / rollover (%)",
        [f"{c} / {share(rs, 'rollover')}" for c, rs in zip(cells, rigid)],
    )
    roll = []
    for rs in runs:
        high = [r["roll"]["abs"]["mean"] for r in rs if r["level"] == "high"]
        roll.append(f"{sum(high) / len(high):.1f}")
    line("mean \\|roll\\| on high (°)", roll)
    for label, values in PAPER.items():
        cells = [f"{v:.1f}" for v in values]
        if label == "success (%)":
            cells = bold_max(cells)
        if label == "stuck (%)":
            best = min(values)
            cells = [f"**{c}**" if v == best else c for c, v in zip(cells, values)]
        line(f"paper: {label}", cells)
    print("\n".join(out))


if __name__ == "__main__":
    main()
