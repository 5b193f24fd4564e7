#!/usr/bin/env python3
"""Runs the code examples of README.md and the documentation (docs/src/**/*.md), so that an
example cannot drift from the code.

    python3 scripts/check_examples.py                  # every page (CI runs this)
    python3 scripts/check_examples.py docs/src/guides/gymnasium.md README.md   # some pages
    python3 scripts/check_examples.py --list           # what would run, and what is skipped

Every ```bash and ```python block runs, as written but for small task counts:

* the blocks of one page run in order, in one fresh folder per page, so a block can use what an
  earlier one wrote (`verti eval ... --out results/x`, then `verti report results/x`); the
  pages of Getting started share one folder, in the book's order, as a reader follows them; the
  folder holds links to the repository's top-level entries and `../shared`, so the paths the
  pages use from the repository root resolve;
* shell blocks run with `bash -euo pipefail`, `verti` on the PATH (target/release/verti), and
  `python` / `python3` the package's virtual environment (python/.venv, or $VERTI_VENV);
* Python blocks run as scripts in that environment, after `import gymnasium as gym` and
  `import verti` (so a fragment that uses them reads as on the page);
* small task counts: every `verti eval` gets `--tasks 1,26` (replacing its own `--tasks`), and
  every `verti.evaluate(...)` / `verti.ray.evaluate(...)` call gets `tasks="1,26"` (replacing its
  own), so a page's 1000-task command checks in seconds (task 26 is the one the pages replay);
* `verti drive`, which waits for a person at a browser, drives headless from a one-line key
  script (`--keys`) for 5 simulated seconds (`--max-time 5 --force`).

A block that cannot run here says so on the line before its fence, with the reason:

    <!-- example: skip (needs torch, which CI does not install) -->

Exit status 1 names each failing block (page and line) with its output.
"""

import argparse
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
FENCE = re.compile(r"^```(\w*)\s*$")
SKIP = re.compile(r"^<!-- example: skip \((?P<why>.+)\) -->$")
TASKS = "1,26"
KEYS = ".examples-keys"
PRELUDE = "import gymnasium as gym\nimport verti\n"
TIMEOUT = 600


class Block:
    def __init__(self, page, line, lang, code, skip):
        self.page, self.line, self.lang, self.code, self.skip = page, line, lang, code, skip

    def where(self):
        return f"{self.page.relative_to(ROOT)}:{self.line}"


def blocks(page):
    """The ```bash and ```python blocks of a page, with the skip reason of the line above each."""
    lines = page.read_text(encoding="utf-8").splitlines()
    out, i = [], 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        lang, start = m.group(1), i
        j = i + 1
        while j < len(lines) and not lines[j].startswith("```"):
            j += 1
        if lang in ("bash", "python"):
            above = lines[start - 1].strip() if start > 0 else ""
            s = SKIP.match(above)
            out.append(Block(page, start + 1, lang, "\n".join(lines[start + 1 : j]) + "\n", s and s.group("why")))
        elif lang not in ("text", "rust", "bibtex", "yaml", "json", "toml", "csv", ""):
            sys.exit(f"{page.relative_to(ROOT)}:{start + 1}: code block of unknown language `{lang}`")
        i = j + 1
    return out


def small_shell(code):
    """`verti eval` commands on two tasks, `verti drive` headless."""
    out = []
    for line in code.splitlines():
        e = re.search(r"(^|[\s;&|(])verti eval\b|verti-cli -- eval\b", line)
        if e:
            cmd, sep, comment = line.partition(" #")
            if re.search(r"--tasks\s+\S+", cmd):
                cmd = re.sub(r"--tasks\s+\S+", f"--tasks {TASKS}", cmd)
            else:
                # at the end of the eval command: before the next chained command, if any
                m = re.compile(r"\s*(&&|\|\||;)\s").search(cmd, e.end())
                at = m.start() if m else len(cmd.rstrip())
                cmd = cmd[:at] + f" --tasks {TASKS}" + cmd[at:]
            line = cmd + sep + comment
        if re.search(r"(^|[\s;&|(])verti drive\b", line) and "--keys" not in line:
            cmd, sep, comment = line.partition(" #")
            line = cmd.rstrip() + f" --keys {KEYS} --max-time 5 --force" + sep + comment
        out.append(line)
    return "\n".join(out) + "\n"


def small_python(code):
    """`verti.evaluate(...)` and `verti.ray.evaluate(...)` calls on two tasks."""
    out, i = [], 0
    for m in re.finditer(r"verti(\.ray)?\.evaluate\(", code):
        if m.start() < i:
            continue
        depth, k = 1, m.end()
        while k < len(code) and depth:
            depth += {"(": 1, ")": -1}.get(code[k], 0)
            k += 1
        args = code[m.end() : k - 1]
        if re.search(r"\btasks\s*=", args):
            args = re.sub(r"\btasks\s*=\s*(\"[^\"]*\"|'[^']*'|\[[^\]]*\]|range\([^)]*\))", f'tasks="{TASKS}"', args)
        else:
            args = args.rstrip() + f', tasks="{TASKS}"'
        out.append(code[i : m.end()] + args + ")")
        i = k
    out.append(code[i:])
    return "".join(out)


def workdir(tmp):
    """A folder that looks like the repository root: links to its entries and to ../shared."""
    work = pathlib.Path(tmp) / "verti"
    work.mkdir()
    for entry in ROOT.iterdir():
        if entry.name in (".git", "target", "results", "report", "runs"):
            continue
        (work / entry.name).symlink_to(entry)
    (work / "target").mkdir()
    (work / "target" / "release").symlink_to(ROOT / "target" / "release")
    shared = ROOT.parent / "shared"
    if shared.exists():
        (pathlib.Path(tmp) / "shared").symlink_to(shared)
    return work


def environment(venv):
    env = dict(os.environ)
    bin_dirs = [str(ROOT / "target" / "release"), str(venv / "bin")]
    env["PATH"] = os.pathsep.join(bin_dirs + [env.get("PATH", "")])
    env["VIRTUAL_ENV"] = str(venv)
    env.pop("PYTHONPATH", None)
    return env


def run_page(page_blocks, venv):
    """Runs the blocks of a page (or of pages that share a folder) in order; returns
    [(block, seconds, error or None)]."""
    done = []
    with tempfile.TemporaryDirectory(prefix="verti-examples-") as tmp:
        work = workdir(tmp)
        (work / KEYS).write_text("0 none\n", encoding="utf-8")
        env = environment(venv)
        for b in page_blocks:
            if b.skip:
                done.append((b, 0.0, None))
                continue
            if b.lang == "bash":
                script, cmd = small_shell(b.code), ["bash", "-euo", "pipefail", "-c"]
                args = cmd + [script]
            else:
                script = PRELUDE + small_python(b.code)
                path = work / f"example_{b.line}.py"
                path.write_text(script, encoding="utf-8")
                args = [str(venv / "bin" / "python"), str(path)]
            t0 = time.monotonic()
            try:
                r = subprocess.run(args, cwd=work, env=env, capture_output=True, text=True, timeout=TIMEOUT)
                error = None if r.returncode == 0 else (
                    f"exit {r.returncode}\n--- as run:\n{script}--- stdout (end):\n{r.stdout[-1500:]}\n"
                    f"--- stderr (end):\n{r.stderr[-2500:]}"
                )
            except subprocess.TimeoutExpired:
                error = f"timed out after {TIMEOUT} s\n--- as run:\n{script}"
            done.append((b, time.monotonic() - t0, error))
    return done


GETTING_STARTED = ["install", "first-evaluation", "first-report", "first-replay"]


def groups(selected):
    """Lists of pages that share a folder: Getting started's in reading order, else one page."""
    generated = {ROOT / "docs/src/reference/cli.md"}  # clap's help: usage lines, not examples
    if selected:
        chosen = [(ROOT / p).resolve() for p in selected]
    else:
        chosen = [ROOT / "README.md"] + sorted(p for p in (ROOT / "docs/src").rglob("*.md") if p not in generated)
    started = [ROOT / f"docs/src/getting-started/{n}.md" for n in GETTING_STARTED]
    together = [p for p in started if p in chosen]
    out = [[p] for p in chosen if p not in started]
    return ([together] if together else []) + out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("pages", nargs="*", help="pages to check (default: README.md and docs/src)")
    ap.add_argument("--list", action="store_true", help="list the blocks and what happens to each")
    a = ap.parse_args()
    venv = pathlib.Path(os.environ.get("VERTI_VENV", ROOT / "python" / ".venv"))
    todo = [[b for p in group for b in blocks(p)] for group in groups(a.pages)]
    todo = [bs for bs in todo if bs]
    if a.list:
        for bs in todo:
            for b in bs:
                print(f"{b.where()}: {b.lang}: " + (f"skip ({b.skip})" if b.skip else "run"))
        return
    if not (ROOT / "target" / "release" / "verti").is_file():
        sys.exit("check_examples: no target/release/verti; run `cargo build --release -p verti-cli` first")
    if not (venv / "bin" / "python").is_file():
        sys.exit(f"check_examples: no virtual environment at {venv}; run `bash python/run_tests.sh` first")
    failures, ran, skipped, t0 = [], 0, 0, time.monotonic()
    for bs in todo:
        for b, seconds, error in run_page(bs, venv):
            if b.skip:
                skipped += 1
                continue
            ran += 1
            status = "ok" if error is None else "FAILED"
            print(f"{b.where()}: {b.lang} {status} ({seconds:.1f} s)", flush=True)
            if error:
                failures.append((b, error))
    for b, error in failures:
        print(f"\n=== {b.where()} ({b.lang}): {error}", file=sys.stderr)
    print(f"check_examples: {ran} blocks ran, {len(failures)} failed, {skipped} skipped (reasons on their pages) "
          f"in {time.monotonic() - t0:.0f} s")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
