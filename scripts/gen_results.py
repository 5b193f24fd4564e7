#!/usr/bin/env python3
"""Fills the generated blocks of the documentation's results pages from the committed runs.

    bash scripts/benchmarks.sh unpack                  # the committed results, uncompressed
    python3 scripts/gen_results.py [VERTI]             # rewrite every generated block
    python3 scripts/gen_results.py [VERTI] --check     # fail if a block is not what the runs give
    python3 scripts/gen_results.py [VERTI] --page docs/src/results/chrono.md   # only that page

A block in a page under docs/src/ reads

    <!-- report: benchmarks/verti-100 pid eh mppi ; section: Table I: outcomes -->
    ...
    <!-- end report -->

and is replaced by that section of `verti report` over the listed runs (a folder and the
system names in it), so a figure on those pages always comes from a committed file and one
command. A block

    <!-- command: python3 scripts/robustness_table.py ; table: 2 -->
    ...
    <!-- end command -->

is replaced by the N-th table (blank-line separated) that a script of scripts/ prints when run
from the repository root. VERTI defaults to target/release/verti.
"""

import pathlib
import re
import shlex
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
BLOCK = re.compile(
    r"(<!-- report: (?P<folder>\S+) (?P<systems>[^;]+?) ; section: (?P<section>[^>]+?) -->\n)"
    r"(?P<body>.*?)"
    r"(<!-- end report -->)",
    re.S,
)
COMMAND = re.compile(
    r"(<!-- command: (?P<command>[^;]+?) ; table: (?P<table>\d+) -->\n)"
    r"(?P<body>.*?)"
    r"(<!-- end command -->)",
    re.S,
)


def command_output(command, cache, where):
    args = shlex.split(command)
    if len(args) < 2 or args[0] != "python3" or not args[1].startswith("scripts/"):
        sys.exit(f"{where}: a command block runs `python3 scripts/...` only, not `{command}`")
    if command not in cache:
        done = subprocess.run(args, cwd=ROOT, check=True, capture_output=True, text=True)
        cache[command] = [t.strip() + "\n" for t in done.stdout.split("\n\n") if t.strip()]
    return cache[command]


def report(verti, folder, systems, cache, tmp):
    key = (folder, tuple(systems))
    if key not in cache:
        runs = [str(ROOT / folder / s) for s in systems]
        for run in runs:
            if not (pathlib.Path(run) / "results.jsonl").is_file():
                sys.exit(f"{run}: no results.jsonl; run `bash scripts/benchmarks.sh unpack` first")
        out = pathlib.Path(tmp) / f"r{len(cache)}"
        subprocess.run(
            [verti, "report", *runs, "--out", str(out)],
            check=True,
            capture_output=True,
            text=True,
        )
        cache[key] = (out / "report.md").read_text(encoding="utf-8")
    return cache[key]


def section(md, name, where):
    m = re.search(rf"^## {re.escape(name)}\n(.*?)(?=^## |\Z)", md, re.S | re.M)
    if not m:
        sys.exit(f"{where}: `verti report` has no section `{name}`")
    return m.group(1).strip() + "\n"


def main():
    argv = sys.argv[1:]
    pages = [ROOT / argv[i + 1] for i, a in enumerate(argv[:-1]) if a == "--page"]
    args = [a for i, a in enumerate(argv) if a not in ("--check", "--page") and (i == 0 or argv[i - 1] != "--page")]
    verti = args[0] if args else str(ROOT / "target/release/verti")
    check = "--check" in sys.argv
    cache, commands, stale, blocks = {}, {}, [], 0
    with tempfile.TemporaryDirectory() as tmp:
        for page in pages or sorted((ROOT / "docs/src").rglob("*.md")):
            text = page.read_text(encoding="utf-8")

            def fill(m, page=page):
                nonlocal blocks
                blocks += 1
                where = page.relative_to(ROOT)
                md = report(verti, m["folder"], m["systems"].split(), cache, tmp)
                body = "\n" + section(md, m["section"].strip(), where) + "\n"
                return m.group(1) + body + m.group(6)

            def fill_command(m, page=page):
                nonlocal blocks
                blocks += 1
                where = page.relative_to(ROOT)
                tables = command_output(m["command"].strip(), commands, where)
                n = int(m["table"])
                if not 1 <= n <= len(tables):
                    sys.exit(f"{where}: `{m['command']}` prints {len(tables)} tables, not {n}")
                return m.group(1) + "\n" + tables[n - 1] + "\n" + m.group(5)

            new = COMMAND.sub(fill_command, BLOCK.sub(fill, text))
            if new != text:
                stale.append(str(page.relative_to(ROOT)))
                if not check:
                    page.write_text(new, encoding="utf-8")
    if check and stale:
        sys.exit(
            "generated results differ from the committed runs in: "
            + ", ".join(stale)
            + " (run python3 scripts/gen_results.py)"
        )
    verb = "checked" if check else ("rewrote " + ", ".join(stale) if stale else "checked")
    print(f"gen_results: {blocks} blocks {verb}")


if __name__ == "__main__":
    main()
