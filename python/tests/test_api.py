"""Worlds, the simulator and evaluation from Python."""

import json
import math
import os

import numpy as np
import pytest

import verti


def test_world_arrays_are_views_without_copies(world):
    h = world.heights
    assert h.shape == (world.size, world.size) == (129, 129)
    assert h.dtype == np.float64
    # a read-only view of the world's own memory: same buffer on every access, no copy
    assert not h.flags.writeable and not h.flags.owndata
    assert h.__array_interface__["data"][0] == world.heights.__array_interface__["data"][0]
    with pytest.raises(ValueError):
        h[0, 0] = 1.0
    # the view keeps the world alive
    w2 = verti.World.generate(seed=0, index=2)
    h2 = w2.heights
    expected = h2.copy()
    del w2
    assert np.array_equal(h2, expected)
    # matches the interpolated surface at the vertices: row 0 north, column 0 west
    half = world.half_extent
    assert world.height_at(-half, half) == pytest.approx(h[0, 0])
    assert world.height_at(half, -half) == pytest.approx(h[-1, -1])
    labels = world.labels
    assert labels.shape == h.shape and labels.dtype == np.uint8 and labels.max() <= 9


def test_world_metadata_tasks_paths_obstacles(world):
    assert world.index == 1 and world.name == "verti-100/001"
    assert world.level in ("low", "mid", "high")
    assert world.terrain_type in ("rigid", "deformable", "mixed")
    assert world.density in ("sparse", "medium", "dense")
    assert world.cell == 1.0 and world.scale == 1.0
    tasks = world.tasks
    assert [t["pair"] for t in tasks] == list(range(10))
    assert [t["task"] for t in tasks] == list(range(1, 11))
    assert tasks[0]["distance"] == pytest.approx(120.0)
    path = world.path(0)
    assert path.shape[1] == 2 and len(path) >= 2
    assert np.allclose(path[0], tasks[0]["start"], atol=1.5) and np.allclose(path[-1], tasks[0]["goal"], atol=1.5)
    obstacles = world.obstacles
    assert obstacles and {o["kind"] for o in obstacles} <= {"rock", "tree"}
    assert obstacles[0]["footprint"].shape[1] == 2
    assert "verti-100/001" in repr(world)


def test_generate_is_deterministic_and_matches_resolve(world):
    again = verti.World.generate(seed=0, index=1)
    assert again == world and again is not world
    assert np.array_equal(again.heights, world.heights)
    named = verti.World.resolve("verti-100:1")
    assert named == world
    other = verti.World.generate(seed=1, index=1)
    assert not np.array_equal(other.heights, world.heights)


def test_save_load_round_trip(world, tmp_path):
    world.save(str(tmp_path / "w"))
    loaded = verti.World.load(str(tmp_path / "w"))
    assert np.array_equal(loaded.heights, world.heights)
    assert np.array_equal(loaded.labels, world.labels)
    assert loaded.tasks == world.tasks


# original Verti-Bench worlds, shipped beside the repository in shared/ (absent elsewhere)
VB_DIR = os.path.join(os.path.dirname(__file__), "..", "..", "..", "shared", "verti-bench-data", "worlds")


@pytest.mark.skipif(not os.path.isdir(VB_DIR), reason="shared/verti-bench-data is absent")
def test_import_verti_bench_world(tmp_path):
    config = os.path.join(VB_DIR, "config12_high.yaml")
    bmp = os.path.join(VB_DIR, "world12.bmp")
    labels = os.path.join(VB_DIR, "labels12_high.npy")
    w = verti.World.import_verti_bench(config, bmp, labels)
    assert w.index == 12 and w.level == "high" and w.heights.shape == (129, 129)
    assert w.heights.max() <= 16.0 + 1e-9 and len(w.tasks) == 10
    # the imported labels are the file's labels
    assert np.array_equal(w.labels, np.load(labels).astype(np.uint8))
    half = verti.World.import_verti_bench(config, bmp, scale=0.5)
    assert half.half_extent == pytest.approx(w.half_extent / 2)
    with pytest.raises(FileNotFoundError, match="nope.yaml"):
        verti.World.import_verti_bench(str(tmp_path / "nope.yaml"), bmp)


def test_sim_step_state_clone(world):
    sim = verti.Sim(world, "hmmwv", start=0)
    s0 = sim.state
    assert s0.time == 0.0 and len(s0.vector) == len(verti.SIM_STATE_FIELDS)
    start = world.tasks[0]["start"]
    assert s0.pose[0] == pytest.approx(start[0]) and s0.pose[1] == pytest.approx(start[1])
    for _ in range(100):
        sim.step(throttle=0.6, brake=0.0, steering=0.0)
    assert sim.time == pytest.approx(1.0)
    assert sim.state.forward_speed > 0.5
    # clone: independent copies that evolve identically
    other = sim.clone()
    for _ in range(50):
        sim.step(0.5, 0.0, 0.2)
        other.step(0.5, 0.0, 0.2)
    assert np.array_equal(sim.state.vector, other.state.vector)
    other.step(0.0, 1.0, 0.0)
    assert other.time > sim.time
    # restore a snapshot
    snap = sim.state
    sim.step(1.0, 0.0, -0.5, dt=0.5)
    sim.state = snap
    assert np.array_equal(sim.state.vector, snap.vector)
    sim.reset()
    assert sim.time == 0.0
    d = snap.to_dict()
    assert set(d) == set(verti.SIM_STATE_FIELDS)


def test_sim_rollout_matches_steps(world):
    a = verti.Sim(world, "hmmwv", start=(0.0, 0.0, math.pi / 4))
    b = a.clone()
    controls = np.tile([0.7, 0.0, 0.1], (30, 1))
    rows = a.rollout(controls, dt=0.01)
    for c in controls:
        b.step(*c, dt=0.01)
    assert rows.shape == (30, len(verti.SIM_STATE_FIELDS))
    assert np.array_equal(rows[-1], b.state.vector)


def test_sim_rejects_bad_input(world):
    sim = verti.Sim(world)
    with pytest.raises(ValueError, match="invalid control `throttle` = 1.5"):
        sim.step(1.5, 0.0, 0.0)
    with pytest.raises(ValueError, match="invalid control `steering` = NaN"):
        sim.step(0.0, 0.0, float("nan"))
    with pytest.raises(ValueError, match="invalid step dt"):
        sim.step(0.5, 0.0, 0.0, dt=-1.0)
    with pytest.raises(ValueError, match="unknown vehicle `tank`; built-in vehicles are: hmmwv"):
        verti.Sim(world, "tank")
    with pytest.raises(ValueError, match="off the map"):
        verti.Sim(world, start=(1000.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="no pair 12"):
        verti.Sim(world, start=12)
    with pytest.raises(TypeError):
        verti.Sim(world, start="north")
    other = verti.Sim(world, start=1)
    with pytest.raises(ValueError, match="belongs to another simulation"):
        sim.state = other.state
    with pytest.raises(ValueError, match="3 columns"):
        sim.rollout(np.zeros((4, 2)))
    assert sim.time == 0.0  # nothing above changed the state


def test_vehicles_and_systems():
    assert "hmmwv" in verti.vehicles()
    names = [s["name"] for s in verti.systems()]
    assert names == ["pid", "eh", "mppi", "oracle", "mppi6", "wmvct", "tal", "tnt", "rl", "mcl", "acl", "pietra", "va"]
    pid = verti.systems()[0]
    speed = next(p for p in pid["params"] if p["name"] == "speed")
    assert speed["type"] == "float" and speed["default"] == 3.0 and speed["max"] == 30.0
    mppi = verti.systems()[2]
    samples = next(p for p in mppi["params"] if p["name"] == "samples")
    assert samples["type"] == "int" and samples["default"] == 800


def test_worlds_generate_from_any_elevation_source():
    rock = verti.World.generate(seed=0, index=3, count=10)
    same = verti.World.generate(seed=0, index=3, count=10, elevation="procedural-rock")
    assert np.array_equal(rock.heights, same.heights)
    swae = verti.World.generate(seed=0, index=3, count=10, elevation="swae-v1",
                                elevation_params={"latent_scale": 0.5})
    assert swae.level == rock.level and not np.array_equal(swae.heights, rock.heights)
    assert len(verti.World.generate_set(seed=0, count=2, elevation="swae-v1")) == 2
    with pytest.raises(ValueError, match="nothing"):
        verti.World.generate(elevation="nothing")
    with pytest.raises(ValueError, match="latent_scale"):
        verti.World.generate(elevation="swae-v1", elevation_params={"latent_scale": 9.0})


def test_world_errors_have_rust_messages(tmp_path):
    with pytest.raises(FileNotFoundError, match="missing: No such file"):
        verti.World.load(str(tmp_path / "missing"))
    with pytest.raises(ValueError, match="has indices 1..=100, not 101"):
        verti.World.generate(index=101)
    with pytest.raises(ValueError, match="scale"):
        verti.World.generate(scale=-1.0)
    with pytest.raises(ValueError, match="unknown world set `nothing-here`"):
        verti.load_worlds("nothing-here")
    with pytest.raises(OverflowError):
        verti.World.generate(seed=-1)


def test_evaluate_returns_trials_and_a_table(world):
    results = verti.evaluate("pid", [world], tasks=[1, 2], jobs=2, max_time=8.0)
    assert [r["task"] for r in results] == [1, 2]
    r = results[0]
    assert r["system"] == "pid" and r["vehicle"] == "hmmwv" and r["world"] == 1
    assert r["outcome"] in verti.OUTCOMES and r["time"] == pytest.approx(8.0) and r["outcome"] == "timeout"
    assert r["path_length"] > 5.0
    # identical for any number of jobs (only the wall time differs)
    again = verti.evaluate("pid", [world], tasks="1-2", jobs=1, max_time=8.0)
    strip = lambda rs: [{k: v for k, v in x.items() if k != "wall_time"} for x in rs]  # noqa: E731
    assert strip(again) == strip(results)
    table = verti.results_table(results)
    assert table["task"] == [1, 2] and table["roll_abs_mean"][0] == r["roll"]["abs"]["mean"]
    assert len({len(c) for c in table.values()}) == 1


def test_learned_planners_run_from_python(world):
    # the shipped models load without training; small plans keep the test quick
    for name in ["tal", "tnt"]:
        r = verti.evaluate(name, [world], tasks=[1], jobs=1, max_time=2.0, params={"samples": 32})
        assert r[0]["system"] == name and r[0]["path_length"] > 0.5


def test_pietra_runs_from_python(world):
    # the risk-aware planner over the shipped pietra-v1; a small plan keeps the test quick
    r = verti.evaluate("pietra", [world], tasks=[1], jobs=1, max_time=2.0, params={"samples": 64, "alpha": 0.8})
    assert r[0]["system"] == "pietra" and r[0]["path_length"] > 0.5
    prior = verti.evaluate("pietra", [world], tasks=[1], jobs=1, max_time=2.0,
                           params={"samples": 64, "prior_only": True})
    assert prior[0]["system"] == "pietra"


def test_va_runs_from_python(world):
    # VertiAdaptor over the shipped va-small-v1, adapting online (recursive least squares) and
    # once on exploration of the world (privileged: verti.evaluate runs a real trial)
    for adapt in ["rls", "once"]:
        r = verti.evaluate("va", [world], tasks=[1], jobs=1, max_time=2.0,
                           params={"samples": 16, "adapt": adapt, "explore_trials": 1, "explore_seconds": 2.0})
        assert r[0]["system"] == "va" and r[0]["error"] is None and r[0]["path_length"] > 0.2


def test_trained_policies_run_from_python(world):
    # rl, mcl and acl: the PPO policies that ship, driven through the benchmark's trial
    strip = lambda rs: [{k: v for k, v in x.items() if k != "wall_time"} for x in rs]  # noqa: E731
    for name in ["rl", "mcl", "acl"]:
        r = verti.evaluate(name, [world], tasks=[1, 2], jobs=1)
        assert [x["system"] for x in r] == [name, name]
        assert all(x["outcome"] in verti.OUTCOMES for x in r)
        assert strip(verti.evaluate(name, [world], tasks=[1, 2], jobs=2)) == strip(r)


def test_evaluate_writes_a_resumable_results_folder(world, tmp_path):
    out = tmp_path / "run"
    first = verti.evaluate("pid", [world], tasks=[3], jobs=1, max_time=3.0, out=str(out))
    assert (out / "results.jsonl").is_file() and len(first) == 1
    with pytest.raises(ValueError, match="already exists"):
        verti.evaluate("pid", [world], tasks=[3], jobs=1, max_time=3.0, out=str(out))
    both = verti.evaluate("pid", [world], tasks=[3, 4], jobs=1, max_time=3.0, out=str(out), resume=True)
    assert [r["task"] for r in both] == [3, 4]
    assert both[0] == first[0]  # resumed, not rerun


def test_selected_tasks_of_a_named_set_build_only_their_worlds(tmp_path):
    # tasks 11 and 12 lie on world 2 of verti-3: only it is built, and run.json records its
    # digest alone; the trials end as they do among the whole set's worlds
    out = tmp_path / "some"
    some = verti.evaluate("pid", "verti-3", tasks="11-12", jobs=1, max_time=5.0, out=str(out))
    record = json.loads((out / "run.json").read_text())
    assert "worlds_digest" not in record
    assert sorted(record["world_digests"]) == ["2"]
    whole = verti.evaluate("pid", verti.load_worlds("verti-3"), tasks="11-12", jobs=1, max_time=5.0)

    def strip(rs):
        return [{k: v for k, v in r.items() if k != "wall_time"} for r in rs]

    assert strip(some) == strip(whole)
    # a resume that adds a task of world 3 builds that world too
    verti.evaluate("pid", "verti-3", tasks="21", jobs=1, max_time=5.0, out=str(out), resume=True)
    record = json.loads((out / "run.json").read_text())
    assert sorted(record["world_digests"]) == ["2", "3"]


def test_evaluate_rejects_bad_arguments(world):
    with pytest.raises(ValueError, match="unknown system `nope`"):
        verti.evaluate("nope", [world])
    with pytest.raises(ValueError, match=r"pid parameter speed: 100 is outside \[0.1, 30\]"):
        verti.evaluate("pid", [world], params={"speed": 100.0})
    with pytest.raises(ValueError, match="mppi parameter samples: `1.5` is not an integer"):
        verti.evaluate("mppi", [world], params={"samples": 1.5})
    with pytest.raises(ValueError, match="pid parameter kp: expected float, got `fast`"):
        verti.evaluate("pid", [world], params={"kp": "fast"})
    with pytest.raises(ValueError, match="not in this world set"):
        verti.evaluate("pid", [world], tasks=[500])
    with pytest.raises(ValueError, match="bad task range"):
        verti.evaluate("pid", [world], tasks="3-1")
    with pytest.raises(ValueError, match="jobs must be at least 1"):
        verti.evaluate("pid", [world], jobs=0)
    with pytest.raises(ValueError, match="max_time"):
        verti.evaluate("pid", [world], max_time=-5.0)
    with pytest.raises(ValueError, match="unknown rules"):
        verti.evaluate("pid", [world], rules="strict")
    with pytest.raises(TypeError):
        verti.evaluate("pid", [1, 2, 3])


@pytest.mark.skipif(os.name != "posix", reason="uses SIGALRM")
def test_ctrl_c_interrupts_a_long_evaluation(world):
    import signal
    import time

    def interrupt(signum, frame):
        raise KeyboardInterrupt

    old = signal.signal(signal.SIGALRM, interrupt)
    signal.setitimer(signal.ITIMER_REAL, 0.5)
    t0 = time.perf_counter()
    try:
        with pytest.raises(KeyboardInterrupt):
            # 10 MPPI trials of up to 600 simulated seconds: minutes of work
            verti.evaluate("mppi", [world], jobs=1, max_time=600.0)
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    assert time.perf_counter() - t0 < 5.0


def test_worlds_pickle_exactly(world):
    import copy
    import pickle

    back = pickle.loads(pickle.dumps(world))
    assert back == world and back is not world
    assert np.array_equal(back.heights, world.heights) and back.tasks == world.tasks
    assert copy.deepcopy(world) is world  # immutable: copies share it


def test_long_calls_release_the_gil(world):
    """While an evaluation runs in a thread, Python code in this thread keeps running."""
    import threading
    import time

    done = threading.Event()
    box = {}

    def work():
        box["results"] = verti.evaluate("pid", [world], tasks="1-10", jobs=1, max_time=60.0)
        done.set()

    t = threading.Thread(target=work)
    t0 = time.perf_counter()
    t.start()
    ticks = 0
    while not done.is_set():
        ticks += 1
        time.sleep(0.001)
    t.join()
    elapsed = time.perf_counter() - t0
    assert len(box["results"]) == 10
    # with the GIL held for the whole call this thread would not tick at all
    assert elapsed > 0.05 and ticks > 10, (elapsed, ticks)


def test_to_dataframe(world):
    pd = pytest.importorskip("pandas")
    results = verti.evaluate("pid", [world], tasks=[5, 6], jobs=1, max_time=5.0)
    df = verti.to_dataframe(results)
    assert isinstance(df, pd.DataFrame) and list(df.task) == [5, 6]
    assert {"outcome", "roll_abs_mean", "pitch_raw_var", "traversal_time"} <= set(df.columns)


def test_world_hash_is_consistent_with_equality(world):
    again = verti.World.generate(seed=0, index=1)
    assert again == world and hash(again) == hash(world)
    assert len({world, again, verti.World.generate(seed=0, index=2)}) == 2


@pytest.mark.skipif(os.name != "posix", reason="uses SIGALRM")
def test_ctrl_c_interrupts_world_generation():
    import signal
    import time

    def interrupt(signum, frame):
        raise KeyboardInterrupt

    old = signal.signal(signal.SIGALRM, interrupt)
    signal.setitimer(signal.ITIMER_REAL, 0.3)
    t0 = time.perf_counter()
    try:
        with pytest.raises(KeyboardInterrupt):
            verti.load_worlds("verti-2000")  # about 40 s of generation on 2 cores
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    # the worlds in flight finish (about 20 ms each), the rest are skipped
    assert time.perf_counter() - t0 < 3.0


@pytest.mark.skipif(os.name != "posix", reason="uses SIGALRM")
def test_ctrl_c_stops_an_evaluation_with_a_results_folder_promptly(world, tmp_path):
    """Issue 10: with out=, Ctrl-C used to wait for the whole batch (MPPI: 50 s); trials cut
    short are not recorded."""
    import signal
    import time

    def interrupt(signum, frame):
        raise KeyboardInterrupt

    old = signal.signal(signal.SIGALRM, interrupt)
    signal.setitimer(signal.ITIMER_REAL, 0.5)
    t0 = time.perf_counter()
    out = tmp_path / "mppi"
    try:
        with pytest.raises(KeyboardInterrupt):
            verti.evaluate("mppi", [world], jobs=1, max_time=600.0, out=str(out))
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    assert time.perf_counter() - t0 < 5.0
    for line in (out / "results.jsonl").read_text().splitlines():
        assert json.loads(line)["outcome"] != "error"


def test_help_documents_every_argument_of_evaluate_and_load_worlds():
    import inspect

    doc = verti.evaluate.__doc__
    for name in inspect.signature(verti.evaluate).parameters:
        assert f"- {name}:" in doc, name
    assert "pysystem" not in doc  # a private module is no help
    assert str(inspect.signature(verti.load_worlds)) == "(spec='verti-100', scale=None)"
