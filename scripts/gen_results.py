#!/usr/bin/env python3
"""Fills the generated blocks of the documentation's results pages from the committed runs.

    bash scripts/benchmarks.sh unpack                  # the committed results, uncompressed
    python3 scripts/gen_results.py [VERTI]             # rewrite every generated block
    python3 scripts/gen_results.py [VERTI] --check     # fail if a block is not what the runs give

A block in a page under docs/src/ reads

    <!-- report: benchmarks/verti-100 pid eh mppi ; section: Table I: outcomes -->
    ...
    <!-- end report -->

and is replaced by that section of `verti report` over the listed runs (a folder and the
system names in it), so a figure on those pages always comes from a committed file and one
command. VERTI defaults to target/release/verti.
"""

import pathlib
import re
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
    args = [a for a in sys.argv[1:] if a != "--check"]
    verti = args[0] if args else str(ROOT / "target/release/verti")
    check = "--check" in sys.argv
    cache, stale, blocks = {}, [], 0
    with tempfile.TemporaryDirectory() as tmp:
        for page in sorted((ROOT / "docs/src").rglob("*.md")):
            text = page.read_text(encoding="utf-8")

            def fill(m, page=page):
                nonlocal blocks
                blocks += 1
                where = page.relative_to(ROOT)
                md = report(verti, m["folder"], m["systems"].split(), cache, tmp)
                body = "\n" + section(md, m["section"].strip(), where) + "\n"
                return m.group(1) + body + m.group(6)

            new = BLOCK.sub(fill, text)
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
