"""The verti-100 tables of the PIETRA and VertiAdaptor result pages
(docs/src/results/pietra.md, vertiadaptor.md): each variant's committed 1000-task run beside
the classical and hybrid systems'.

    bash scripts/benchmarks.sh unpack && python3 scripts/method_tables.py

Prints two tables (PIETRA's, then VertiAdaptor's): success (%), success per elevation level,
rollover, stuck and timeout (%), and the mean traversal time of the successful trials (s). A run
with fewer than 1000 results says how many it has. Reads `benchmarks/verti-100/<run>/results.jsonl`.
"""

from pathlib import Path

from run_rows import rows, share, success_by_level

PIETRA = [
    ("PIETRA (`pietra-v1`, dirt-only prior)", "pietra"),
    ("PIETRA, semantics-aware prior", "pietra-semantics"),
    ("PIETRA, α 0.8 (chosen on validation worlds, below)", "pietra-alpha08"),
    ("physics prior alone (`prior_only=true`)", "pietra-prior"),
    ("PID", "pid"),
    ("MPPI", "mppi"),
    ("TAL", "tal"),
    ("TNT", "tnt"),
    ("VA† (every 5 s)", "va-every"),
]
VA = [
    ("VA* (once)", "va"),
    ("VA† (every 5 s)", "va-every"),
    ("VA-RLS", "va-rls"),
    ("PID", "pid"),
    ("TAL", "tal"),
    ("TNT", "tnt"),
]


RUNS = Path(__file__).resolve().parent.parent / "benchmarks" / "verti-100"


def table(entries):
    lines = [
        "| 1000 tasks | success | low | mid | high | rollover | stuck | timeout | traversal time (s) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for label, run in entries:
        rs = rows(RUNS / run)
        if not rs:
            lines.append(f"| {label} | not run | | | | | | | |")
            continue
        n = len(rs)
        levels = success_by_level(rs)
        times = [r["traversal_time"] for r in rs if r["outcome"] == "success" and r.get("traversal_time")]
        time = f"{sum(times) / len(times):.2f}" if times else "—"
        note = "" if n == 1000 else f" ({n} tasks)"
        lines.append(
            f"| {label} | {share(rs, 'success')} %{note} | {' | '.join(levels)} | "
            f"{share(rs, 'rollover')} | {share(rs, 'stuck')} | {share(rs, 'timeout')} | {time} |"
        )
    return "\n".join(lines) + "\n"


def main():
    print(table(PIETRA))
    print(table(VA))


if __name__ == "__main__":
    main()
