"""Evaluate the PID system from Python and analyse the trials with pandas.

    pip install pandas
    python examples/pid_eval_pandas.py [--tasks 1-100] [--jobs 2]

`verti.evaluate` runs the trials in parallel in Rust (GIL released, Ctrl-C stops it) and
returns one dict per trial; `verti.to_dataframe` flattens them into a DataFrame
(`verti.results_table` gives the same columns as a dict without pandas).
"""

import argparse

import verti


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--worlds", default="verti-100")
    p.add_argument("--tasks", default="1-100", help="task numbers, e.g. 1-1000 or 1,5,10-20")
    p.add_argument("--jobs", type=int, default=None, help="parallel trials (default: all cores)")
    p.add_argument("--speed", type=float, default=3.0, help="PID target speed, full-scale m/s")
    p.add_argument("--csv", default=None, help="also write the table here")
    args = p.parse_args()

    results = verti.evaluate("pid", args.worlds, tasks=args.tasks, jobs=args.jobs, params={"speed": args.speed})
    df = verti.to_dataframe(results)
    print(df[["task", "world", "level", "terrain_type", "density", "outcome", "time", "path_length", "roll_abs_mean"]].head(10).to_string(index=False))
    print()
    print("success rate by elevation level and obstacle density:")
    print(df.assign(success=df.outcome == "success").pivot_table(index="level", columns="density", values="success", aggfunc="mean").round(2).to_string())
    print()
    print("outcomes:", df.outcome.value_counts().to_dict())
    ok = df[df.outcome == "success"]
    if len(ok):
        print(f"successful trials: mean time {ok.traversal_time.mean():.1f} s, mean |roll| {ok.roll_abs_mean.mean():.2f} deg, "
              f"mean |pitch| {ok.pitch_abs_mean.mean():.2f} deg")
    if args.csv:
        df.to_csv(args.csv, index=False)
        print(f"wrote {args.csv}")


if __name__ == "__main__":
    main()
