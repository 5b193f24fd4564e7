"""Distributed evaluation on a Ray cluster: ``verti.ray.evaluate``.

The tasks are cut into chunks; each chunk is one Ray task that runs ``verti.evaluate`` on a
worker and sends back the exact JSON lines the Rust evaluator wrote. The driver appends each
finished chunk's lines to ``out/results.jsonl`` once, so a worker that dies mid-chunk costs
only a retry of that chunk (Ray re-runs it elsewhere): no task is lost and none is written
twice. The first chunk runs on the driver, which writes ``run.json`` (and checks every argument
before the cluster is used); a final ``verti.evaluate(..., resume=True)`` over the whole
selection runs nothing, records the full selection in ``run.json`` and returns every result,
so the directory is exactly what ``verti eval`` writes (identical but for wall time) and resumes
or reports like one.

Ray is optional (``pip install ray``); nothing else in verti imports it.

>>> import ray, verti.ray
>>> ray.init(num_cpus=2)                       # or ray.init(address="auto") on a cluster
>>> rows = verti.ray.evaluate("tal", "verti-100", out="results/tal", chunk=10)
"""

from __future__ import annotations

import json
import os
import signal
import tempfile
from typing import Any, Callable, Dict, List, Optional, Sequence, Set, Union

import verti

TasksArg = Union[None, str, int, Sequence[int]]


def _parse_tasks(spec: TasksArg) -> List[int]:
    """Task numbers of ``"1-10,15"``-style text, an int or a list; [] means all."""
    if spec is None:
        return []
    if isinstance(spec, int):
        return [spec]
    if isinstance(spec, str):
        if spec.strip() == "all":
            return []
        out: Set[int] = set()
        for part in spec.split(","):
            a, _, b = part.strip().partition("-")
            lo, hi = int(a), int(b or a)
            if lo < 1 or hi < lo:
                raise ValueError(f"bad task range {part!r} in {spec!r}")
            out.update(range(lo, hi + 1))
        return sorted(out)
    return sorted({int(t) for t in spec})


def _task_numbers(worlds: str, scale: Optional[float], tasks: TasksArg) -> List[int]:
    every = sorted(t["task"] for w in verti.load_worlds(worlds, scale) for t in w.tasks)
    wanted = _parse_tasks(tasks)
    if not wanted:
        return every
    missing = sorted(set(wanted) - set(every))
    if missing:
        raise ValueError(f"{len(missing)} selected task(s) are not in {worlds!r} (e.g. {missing[:5]})")
    return wanted


def _run_chunk(system: str, worlds: str, tasks: List[int], settings: Dict[str, Any]) -> List[str]:
    """Runs `tasks` here and returns the results as the evaluator's own JSON lines."""
    hook = settings.pop("_test_hook", None)
    if hook is not None:
        hook(tasks)
    with tempfile.TemporaryDirectory(prefix="verti-ray-") as d:
        out = os.path.join(d, "run")
        verti.evaluate(system, worlds, tasks=tasks, jobs=1, out=out, **settings)
        with open(os.path.join(out, "results.jsonl"), encoding="utf-8") as f:
            return [line for line in f.read().splitlines() if line.strip()]


class KillOnce:
    """A test aid for ``_test_hook``: the first worker to start the chunk holding ``task``
    kills itself with SIGKILL (as an OOM killer or a lost node would), leaving ``marker`` so
    that Ray's retry of the chunk runs normally."""

    def __init__(self, task: int, marker: str):
        self.task = task
        self.marker = marker

    def __call__(self, tasks: List[int]) -> None:
        if self.task in tasks and not os.path.exists(self.marker):
            with open(self.marker, "w", encoding="utf-8") as f:
                f.write(str(os.getpid()))
            os.kill(os.getpid(), signal.SIGKILL)


def _done_tasks(path: str) -> set:
    if not os.path.exists(path):
        return set()
    done = set()
    with open(path, encoding="utf-8") as f:
        for line in f:
            line = line.strip()
            if line:
                try:
                    done.add(json.loads(line)["task"])
                except (ValueError, KeyError):
                    pass  # a torn last line: the final resume drops it and runs the task
    return done


def evaluate(
    system: str = "pid",
    worlds: str = "verti-100",
    tasks: TasksArg = None,
    *,
    out: str,
    chunk: int = 10,
    max_retries: int = 3,
    resume: bool = False,
    vehicle: Optional[str] = None,
    params: Optional[Dict[str, Any]] = None,
    rules: str = "paper",
    max_time: float = 60.0,
    seed: int = 0,
    scale: Optional[float] = None,
    start: str = "settled",
    perception: str = "none",
    progress: Optional[Callable[[int, int], None]] = None,
    _test_hook: Optional[Callable[[List[int]], None]] = None,
) -> List[Dict[str, Any]]:
    """Evaluates a built-in system on a Ray cluster into ``out`` (required: the results live
    there); returns one dict per trial, sorted by task, like ``verti.evaluate``.

    Args:
        system, worlds, tasks, vehicle, params, rules, max_time, seed, scale, start,
            perception: as for ``verti.evaluate`` (``worlds`` must name a set every worker can
            load: a built-in set, or a path on shared storage).
        out: run directory (as ``verti eval --out``); with ``resume=True`` a finished part is
            kept and only the rest runs.
        chunk: tasks per Ray task (a killed worker re-runs at most this many).
        max_retries: Ray retries of a chunk whose worker died.
        progress: called as ``progress(done, total)`` after each chunk.

    Ray must be initialised (``ray.init(...)``) before the call.
    """
    import ray  # optional dependency, imported only here

    if not ray.is_initialized():
        raise RuntimeError("call ray.init(...) before verti.ray.evaluate")
    if not isinstance(system, str):
        raise TypeError("verti.ray.evaluate runs built-in systems by name (Python objects do not travel)")
    if chunk < 1:
        raise ValueError("chunk must be at least 1")
    settings: Dict[str, Any] = dict(
        vehicle=vehicle,
        params=params,
        rules=rules,
        max_time=max_time,
        seed=seed,
        scale=scale,
        start=start,
        perception=perception,
    )
    selection = _task_numbers(worlds, scale, tasks)
    results_path = os.path.join(out, "results.jsonl")
    if os.path.exists(results_path) and not resume:
        raise ValueError(f"{results_path} already exists: pass resume=True to continue that run")
    # the first chunk runs here: it writes run.json (or checks it on resume) and fails fast on
    # any bad argument before the cluster is used
    first = selection[:chunk]
    verti.evaluate(system, worlds, tasks=first, jobs=1, out=out, resume=True, **settings)
    done = _done_tasks(results_path)
    todo = [t for t in selection if t not in done]
    chunks = [todo[i : i + chunk] for i in range(0, len(todo), chunk)]
    remote = ray.remote(num_cpus=1, max_retries=max_retries)(_run_chunk)
    worker_settings = dict(settings, _test_hook=_test_hook) if _test_hook else settings
    pending = {remote.remote(system, worlds, c, worker_settings): c for c in chunks}
    finished = len(selection) - len(todo)
    with open(results_path, "a", encoding="utf-8") as f:
        while pending:
            ready, _ = ray.wait(list(pending), num_returns=1)
            for ref in ready:
                pending.pop(ref)
                lines = ray.get(ref)
                f.write("".join(line + "\n" for line in lines))
                f.flush()
                finished += len(lines)
                if progress is not None:
                    progress(finished, len(selection))
    # nothing left to run: this records the whole selection and returns every result
    return verti.evaluate(system, worlds, tasks=selection, jobs=1, out=out, resume=True, **settings)
