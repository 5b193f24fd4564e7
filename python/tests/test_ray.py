"""verti.ray.evaluate on a local 2-CPU Ray instance, with a worker killed mid-run."""

import json
import os

import pytest

ray = pytest.importorskip("ray")

import verti  # noqa: E402
import verti.ray  # noqa: E402


@pytest.fixture(scope="module")
def local_ray():
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    yield
    ray.shutdown()


def _lines(path):
    with open(path, encoding="utf-8") as f:
        return [json.loads(line) for line in f if line.strip()]


def _strip(rows):
    return sorted(({k: v for k, v in r.items() if k != "wall_time"} for r in rows), key=lambda r: r["task"])


def test_a_killed_worker_loses_no_task_and_duplicates_none(local_ray, tmp_path):
    out = tmp_path / "ray-run"
    marker = tmp_path / "killed"
    seen = []
    rows = verti.ray.evaluate(
        "pid",
        "verti-4",
        tasks="1-24",
        out=str(out),
        chunk=4,
        progress=lambda done, total: seen.append((done, total)),
        _test_hook=verti.ray.KillOnce(task=14, marker=str(marker)),
    )
    # the worker running task 14's chunk really died, and its chunk was re-run
    assert marker.exists()
    on_disk = _lines(out / "results.jsonl")
    tasks = [r["task"] for r in on_disk]
    assert sorted(tasks) == list(range(1, 25)), tasks  # none lost, none twice
    local = verti.evaluate("pid", "verti-4", tasks="1-24", jobs=2)
    assert _strip(on_disk) == _strip(local) == _strip(rows)
    assert seen[-1] == (24, 24)
    # the directory is an ordinary run: it records the whole selection and resumes as finished
    run = json.loads((out / "run.json").read_text())
    assert run["tasks"] == "1-24" and run["system"] == "pid"
    again = verti.evaluate("pid", "verti-4", tasks="1-24", out=str(out), resume=True)
    assert len(again) == 24


def test_resume_runs_only_the_rest_and_bad_input_fails_before_the_cluster(local_ray, tmp_path):
    out = tmp_path / "partial"
    verti.evaluate("pid", "verti-4", tasks="1-6", out=str(out))
    rows = verti.ray.evaluate("pid", "verti-4", tasks="1-12", out=str(out), chunk=3, resume=True)
    assert [r["task"] for r in rows] == list(range(1, 13))
    assert len(_lines(out / "results.jsonl")) == 12
    with pytest.raises(ValueError, match="already exists"):
        verti.ray.evaluate("pid", "verti-4", tasks="1-12", out=str(out))
    with pytest.raises(ValueError):
        verti.ray.evaluate("nonexistent-system", "verti-4", tasks="1-4", out=str(tmp_path / "bad"))
    with pytest.raises(ValueError, match="not in"):
        verti.ray.evaluate("pid", "verti-4", tasks="1-9999", out=str(tmp_path / "bad2"))
