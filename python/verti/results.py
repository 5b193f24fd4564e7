"""Evaluation results as tables.

`verti.evaluate` returns one dict per trial with the fields of `results.jsonl` (nested for
the per-trial statistics, e.g. ``result["roll"]["abs"]["mean"]``). These helpers flatten them
into columns that pandas (optional) or any table tool takes directly.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Dict, Iterable, List

if TYPE_CHECKING:
    import pandas


def flatten_result(result: Dict[str, Any], prefix: str = "") -> Dict[str, Any]:
    """One trial as a flat dict: nested keys are joined with ``_`` (``roll_abs_mean``)."""
    flat: Dict[str, Any] = {}
    for key, value in result.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            flat.update(flatten_result(value, name + "_"))
        else:
            flat[name] = value
    return flat


def results_table(results: Iterable[Dict[str, Any]]) -> Dict[str, List[Any]]:
    """Trials as a dict of equally long columns (``pandas.DataFrame(results_table(r))``).

    A field missing from some trial (e.g. ``traversal_time`` of failures is None) is None there.
    """
    rows = [flatten_result(r) for r in results]
    columns: List[str] = []
    for row in rows:
        for key in row:
            if key not in columns:
                columns.append(key)
    return {c: [row.get(c) for row in rows] for c in columns}


def to_dataframe(results: Iterable[Dict[str, Any]]) -> pandas.DataFrame:
    """Trials as a pandas DataFrame (needs pandas: ``pip install pandas``)."""
    try:
        import pandas as pd
    except ImportError as e:  # pandas is optional
        raise ImportError("verti.to_dataframe needs pandas: pip install pandas (or use verti.results_table)") from e
    return pd.DataFrame(results_table(results))
