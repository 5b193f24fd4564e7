"""Reading committed runs for the documentation's table scripts (method_tables.py,
vehicles_table.py, pietra_validation_table.py, va_table4.py, robustness_table.py): the results
of a run, the shares the tables print, and paired comparisons."""

import json
import math
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


def paired(a, b):
    """Of the tasks both {task: outcome} maps hold: how many only `a` reached and how many only
    `b` reached."""
    both = a.keys() & b.keys()
    only_a = sum(a[t] == "success" and b[t] != "success" for t in both)
    only_b = sum(a[t] != "success" and b[t] == "success" for t in both)
    return only_a, only_b


def sign_test(a, b):
    """Two-sided exact sign test of `a` wins against `b` wins."""
    n = a + b
    if n == 0:
        return 1.0
    tail = sum(math.comb(n, i) for i in range(min(a, b) + 1)) / 2**n
    return min(1.0, 2 * tail)
