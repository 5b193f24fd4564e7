"""verti.replay: 3-D recordings of an evaluated trial, as a web page, JSON and Rerun's .rrd."""

import json
import os
import shutil
import subprocess
import sys

import pytest

import verti


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("replay") / "run"
    rows = verti.evaluate("pid", "verti-4", tasks="1-2", out=str(out))
    return out, {r["task"]: r for r in rows}


def test_html_and_json_hold_the_trial(run_dir, tmp_path):
    run, recorded = run_dir
    page = tmp_path / "t1.html"
    result = verti.replay(str(run), 1, str(page))
    assert result["outcome"] == recorded[1]["outcome"] and result["time"] == recorded[1]["time"]
    text = page.read_text()
    assert "<canvas" in text and '"frames"' in text and "VERTI_DATA" not in text
    rec = json.loads(verti.replay(run, 1, tmp_path / "t1.json") and (tmp_path / "t1.json").read_text())
    assert len(rec["frames"]) > 10 and len(rec["frames"][0]["wheels"]) == 4
    assert rec["frames"][-1]["t"] == pytest.approx(recorded[1]["time"])
    with pytest.raises(ValueError, match="supported"):
        verti.replay(str(run), 1, str(tmp_path / "t1.png"))
    with pytest.raises(ValueError, match="task 99"):
        verti.replay(str(run), 99, str(tmp_path / "x.html"))


def test_rrd_verifies_with_rerun_tooling(run_dir, tmp_path):
    pytest.importorskip("rerun")
    rerun = shutil.which("rerun", path=os.path.dirname(sys.executable)) or shutil.which("rerun")
    assert rerun, "rerun-sdk installs the rerun command"
    run, _ = run_dir
    rrd = tmp_path / "t2.rrd"
    verti.replay(str(run), 2, str(rrd))
    env = dict(os.environ, RERUN_ANALYTICS="0")
    verify = subprocess.run([rerun, "rrd", "verify", str(rrd)], capture_output=True, text=True, env=env)
    assert verify.returncode == 0, verify.stdout + verify.stderr
    printed = subprocess.run([rerun, "rrd", "print", "-v", str(rrd)], capture_output=True, text=True, env=env)
    for entity in ("/world/terrain", "/world/vehicle/body", "/world/vehicle/wheels", "/plots/speed", "/plots/sinkage_cm"):
        assert entity in printed.stdout, entity


def test_a_run_on_worlds_in_memory_replays_with_the_same_worlds(tmp_path):
    """A run made on a list of World objects records no set name: replay says how to pass the
    worlds, replays with them, and refuses other worlds."""
    worlds = verti.load_worlds("verti-3")
    run = tmp_path / "run"
    rows = verti.evaluate("pid", worlds, tasks="1", out=str(run))
    with pytest.raises(ValueError, match=r"3 worlds.*worlds="):
        verti.replay(run, 1, tmp_path / "a.html")
    result = verti.replay(run, 1, tmp_path / "a.html", worlds=worlds)
    assert result["outcome"] == rows[0]["outcome"] and result["time"] == rows[0]["time"]
    # the same worlds by name, resolved at the run's scale
    by_name = verti.replay(run, 1, tmp_path / "n.html", worlds="verti-3")
    assert by_name["time"] == rows[0]["time"]
    with pytest.raises(ValueError, match="not those the run"):
        verti.replay(run, 1, tmp_path / "b.html", worlds=verti.load_worlds("verti-3-s1"))
