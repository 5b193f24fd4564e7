"""Reading committed runs for the documentation's table scripts (method_tables.py,
vehicles_table.py): the results of a run, and the shares the tables print."""

import json
from pathlib import Path

LEVELS = ["low", "mid", "high"]


def rows(run, tasks=None):
    """The results of the run in folder `run` (restricted to `tasks`), or [] if it has none."""
    file = Path(run) / "results.jsonl"
    if not file.exists():
        return []
    out = (json.loads(line) for line in file.open() if line.strip())
    return [r for r in out if tasks is None or r["task"] in tasks]


def pct(part, whole):
    return f"{100.0 * part / whole:.1f}" if whole else "—"


def share(rs, outcome):
    """Percentage of `rs` that ended in `outcome`, formatted."""
    return pct(sum(r["outcome"] == outcome for r in rs), len(rs))


def success_by_level(rs):
    """Success percentage at each elevation level, formatted, low to high."""
    return [share([r for r in rs if r["level"] == level], "success") for level in LEVELS]
