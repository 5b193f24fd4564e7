"""Re-runs, in committed evaluations, only the tasks on one terrain type, or only given tasks,
after an engine change that provably touches no other (e.g. the rigid/soil edges, which exist
only on mixed worlds; a change of the settled start, which moves only some starts), or every
task after a change of the vehicle itself.

    python3 scripts/rerun_terrain.py --bin target/release/verti --terrain mixed [RUN_DIR ...]
    python3 scripts/rerun_terrain.py --bin target/release/verti \
        --tasks hmmwv@verti-100=671,690 --tasks m113@verti-100=28,76 [RUN_DIR ...]
    python3 scripts/rerun_terrain.py --bin target/release/verti --all RUN_DIR ...

`--tasks VEHICLE@WORLDS=LIST` names the tasks to redo in runs of that vehicle on that world set
(`worlds` as run.json records it); a run's other tasks, and runs of other vehicles or sets,
are left alone.

For each run folder (default: every benchmarks/**/run.json whose results hold such tasks) it
removes those tasks' results, lets `verti eval --resume --out DIR` recompute them from the
run's own record (system, parameters, vehicle, worlds, tasks), and sorts the results by task.
The other results stay as they are: run the full evaluation of one cheap system with the new
binary and compare digests (`scripts/results_digest.py`) to check that they would come out the
same. Resumable: a folder already done is recomputed only for tasks still missing. Then
`bash scripts/benchmarks.sh pack`.

`--all` re-runs every task of each named run (it names no default: say which runs). A changed
vehicle changes the run's record (its vehicle file and digest), so the run cannot resume in
place: it is made afresh in benchmarks/in-progress/<the run's path under benchmarks/>, from the
same arguments, where an interrupted run resumes, and when every task is done its run.json and
results.jsonl replace the committed ones.
"""

import argparse
import json
import shutil
import subprocess
import sys
import time
from pathlib import Path


def lines(path):
    """The result lines of `path`, as written (kept byte for byte), with their parsed rows."""
    return [(line, json.loads(line)) for line in path.open() if line.strip()]


def value(v):
    """A recorded parameter as `--param` takes it."""
    if isinstance(v, bool):
        return "true" if v else "false"
    return str(v)


def eval_args(run):
    """The `verti eval` arguments that reproduce the run recorded in `run`/run.json (the resume
    check refuses any difference, so a wrong guess cannot mix runs)."""
    rec = json.loads((run / "run.json").read_text())
    out = ["--system", rec["system"], "--vehicle", rec["vehicle"], "--worlds", rec["worlds"]]
    out += ["--scale", repr(rec["scale"]), "--compat", rec["rules"], "--seed", str(rec["seed"])]
    out += ["--max-time", repr(rec["max_time"]), "--start", rec["start"]]
    if rec.get("tasks") not in (None, "all"):
        out += ["--tasks", rec["tasks"]]
    for k, v in rec["params"].items():
        out += ["--param", f"{k}={value(v)}"]
    perception = rec.get("perception")
    if perception:
        name = perception["name"] if isinstance(perception, dict) else perception
        out += ["--perception", name if name in ("low", "medium", "high") else f"docs/perception/{name}.yaml"]
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bin", required=True, help="the verti binary to evaluate with")
    ap.add_argument("--terrain", choices=["rigid", "deformable", "mixed"])
    ap.add_argument("--tasks", action="append", default=[], metavar="VEHICLE@WORLDS=LIST",
                    help="redo these tasks (comma-separated) in runs of VEHICLE on WORLDS")
    ap.add_argument("--all", action="store_true", help="redo every task (a changed vehicle)")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--skip", action="append", default=[], help="skip run folders containing this")
    ap.add_argument("runs", nargs="*", help="run folders (default: all under benchmarks/)")
    args = ap.parse_args()
    if [args.terrain is not None, bool(args.tasks), args.all].count(True) != 1:
        ap.error("give --terrain, --tasks or --all (one of them)")
    if args.all and not args.runs:
        ap.error("--all re-runs every task: name the run folders")
    chosen = {}
    for spec in args.tasks:
        key, _, numbers = spec.rpartition("=")
        vehicle, _, worlds = key.partition("@")
        try:
            tasks = {int(n) for n in numbers.split(",") if n}
        except ValueError:
            tasks = set()
        if not (vehicle and worlds and tasks):
            ap.error(f"--tasks {spec}: expected VEHICLE@WORLDS=LIST (LIST: task numbers, comma-separated)")
        chosen[(vehicle, worlds)] = tasks
    root = Path(__file__).resolve().parent.parent
    runs = [Path(r) for r in args.runs] or sorted(
        p.parent for p in (root / "benchmarks").rglob("run.json")
    )
    for run in runs:
        if any(s in str(run) for s in args.skip):
            print(f"skip {run}", flush=True)
            continue
        results = run / "results.jsonl"
        if not results.exists():
            print(f"{run}: no results.jsonl (bash scripts/benchmarks.sh unpack)", file=sys.stderr)
            sys.exit(2)
        rs = lines(results)
        if args.all:
            redo_all(args, root, run, len(rs))
            continue
        if args.terrain:
            keep = [(line, r) for line, r in rs if r.get("terrain_type") != args.terrain]
        else:
            rec = json.loads((run / "run.json").read_text())
            redo_tasks = chosen.get((rec["vehicle"], rec["worlds"]), set())
            keep = [(line, r) for line, r in rs if r["task"] not in redo_tasks]
        redo = len(rs) - len(keep)
        if redo == 0:
            continue
        start = time.time()
        with results.open("w") as f:
            f.writelines(line for line, _ in keep)
        resume_into(args, root, run, run, len(rs))
        what = args.terrain or "chosen"
        print(f"{run}: {redo} {what} tasks in {time.time() - start:.0f} s", flush=True)


def redo_all(args, root, run, count):
    """Every task of `run` afresh in benchmarks/in-progress/..., then moved over the run."""
    run = run.resolve()
    work = root / "benchmarks" / "in-progress" / run.relative_to(root / "benchmarks")
    work.mkdir(parents=True, exist_ok=True)
    start = time.time()
    resume_into(args, root, run, work, count)
    shutil.copyfile(work / "run.json", run / "run.json")
    shutil.rmtree(work)
    # Leave no empty folders behind (benchmarks/in-progress/vb80/ once its last run is moved).
    holder = root / "benchmarks" / "in-progress"
    parent = work.parent
    while parent != holder and not any(parent.iterdir()):
        parent.rmdir()
        parent = parent.parent
    print(f"{run}: all {count} tasks in {time.time() - start:.0f} s", flush=True)


def resume_into(args, root, run, out, count):
    """Let `verti eval --resume --out OUT` finish `run`'s record there, then write OUT's results,
    sorted by task, as `run`'s (exits if the evaluation fails or the count is not `count`)."""
    done = subprocess.run(
        [args.bin, "eval", *eval_args(run), "--resume", "--out", str(out), "--jobs", str(args.jobs)],
        capture_output=True,
        text=True,
        cwd=root,
    )
    if done.returncode != 0:
        print(f"{run}: verti eval failed:\n{done.stderr}", file=sys.stderr)
        sys.exit(1)
    after = sorted(lines(out / "results.jsonl"), key=lambda lr: lr[1]["task"])
    if len(after) != count:
        print(f"{run}: {len(after)} results after, {count} before", file=sys.stderr)
        sys.exit(1)
    with (run / "results.jsonl").open("w") as f:
        f.writelines(line for line, _ in after)


if __name__ == "__main__":
    main()
