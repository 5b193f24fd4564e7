"""Datasets written by ``verti data generate`` (random exploration, failures, expert).

>>> frame, manifest = verti.data.load("/tmp/r10")
>>> manifest["kind"], manifest["hours"]
>>> frame[frame["last"]]["outcome"].value_counts()

The files are read by verti's Rust reader (no pyarrow needed); every file is checked against the
schema and the manifest's checksums, and a damaged one raises ValueError naming it.
"""

import json

import numpy as np

from . import _verti


def load(path):
    """Loads a dataset directory.

    Returns ``(data, manifest)``: ``data`` is a pandas DataFrame (one row per control step, the
    columns in schema order) when pandas is installed, else a dict of column name -> numpy
    array; ``manifest`` is ``manifest.yaml`` as a dict. The ``outcome`` column holds the trial's
    outcome on its last row (``last`` is True there) and is missing elsewhere (None in the
    dict of arrays; pandas shows it as a missing value).
    """
    columns, manifest = _verti._load_dataset(str(path))
    columns["outcome"] = np.array(columns["outcome"], dtype=object)
    manifest = json.loads(manifest)
    try:
        import pandas
    except ImportError:
        return columns, manifest
    return pandas.DataFrame(columns), manifest


def trials(data):
    """Splits ``data`` (as returned by :func:`load`) into per-trial pieces, in order."""
    last = np.asarray(data["last"])
    ends = np.flatnonzero(last) + 1
    starts = np.concatenate([[0], ends[:-1]])
    if hasattr(data, "iloc"):
        return [data.iloc[a:b] for a, b in zip(starts, ends)]
    return [{k: v[a:b] for k, v in data.items()} for a, b in zip(starts, ends)]


def generate(out, kind="random", hours=10.0, worlds="verti-100-s1", vehicle="hmmwv", seed=0,
             rate=10.0, profile="paper", max_trial_seconds=300.0, force=False):
    """Generates random exploration (``kind="random"``) or the failure cases harvested from it
    (``kind="failures"``) into the directory ``out``, exactly as ``verti data generate KIND``
    does with the same settings. Evaluation worlds are refused. Returns the manifest as a dict.
    Expert data need a system: use ``verti data generate expert``.
    """
    return json.loads(_verti._generate_dataset(
        str(out), kind, float(hours), worlds, vehicle, int(seed), float(rate), profile,
        float(max_trial_seconds), bool(force)))
