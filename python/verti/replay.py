"""``verti.replay``: one evaluated trial, re-run and recorded in 3-D."""

from __future__ import annotations

import os
import tempfile
from typing import Any, Dict, Optional, Sequence, Union

from . import _verti
from ._verti import World


def replay(
    run: str, task: int, out: str, worlds: Optional[Union[str, World, Sequence[World]]] = None
) -> Dict[str, Any]:
    """Re-runs task ``task`` of the run in directory ``run`` (written by ``verti eval`` or
    ``verti.evaluate(..., out=...)``; trials are deterministic) and records it in 3-D.

    ``out`` picks the format by its extension:

    * ``.html``: a self-contained web page (WebGL, no server): terrain coloured by class,
      obstacles, the vehicle body and wheels, path, trail, and speed, roll, pitch, throttle,
      steering and wheel sinkage on one timeline;
    * ``.rrd``: a Rerun recording (needs ``pip install rerun-sdk``; open with ``rerun FILE``);
    * ``.json``: the recording itself.

    ``worlds`` (a ``World``, a list of them or a set name) replaces the world set the run
    names, checked by content against the run's record: a run made by ``verti.evaluate`` on
    worlds held in memory records no set name, so replay it with the same worlds.

    Returns the replayed trial's result dict (as ``verti.evaluate`` returns them).
    """
    run, out = os.fspath(run), os.fspath(out)
    if out.endswith(".rrd"):
        from . import rerun  # optional dependency, imported only here

        with tempfile.TemporaryDirectory(prefix="verti-replay-") as d:
            path = os.path.join(d, "recording.json")
            result = _verti._replay(run, task, path, worlds)
            rerun.save_rrd(path, out)
        return result
    return _verti._replay(run, task, out, worlds)
