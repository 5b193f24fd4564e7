#!/usr/bin/env python3
"""Arrows only go down: finds import cycles between the files of each crate and between crates.

A file imports another when it names an item through `crate::a::b`, `super::x` or `self::x`
(in `use` declarations and in paths in code); the target is the deepest module file the path
reaches. Declaring a child module (`mod x;`) is not an import, and neither is a `#[cfg(test)]`
module's use of its parent (tests sit below what they test). Prints each cycle (a strongly
connected group of files) and exits 1 if there is any, or more than `--allow` of them.

    python3 scripts/check_layers.py            # all crates
    python3 scripts/check_layers.py --allow N  # tolerate N while a refactor is under way
"""
import argparse
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
PATH_RE = re.compile(r"\b(crate|super|self)((?:::[A-Za-z_][A-Za-z0-9_]*)+)")
USE_GROUP_RE = re.compile(r"\buse\s+(crate|super|self)((?:::[A-Za-z_][A-Za-z0-9_]*)*)::\{([^;]*)\};", re.S)


def module_of(src: pathlib.Path, f: pathlib.Path):
    rel = f.relative_to(src).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] in ("lib", "main", "mod"):
        parts = parts[:-1]
    return tuple(parts)


def strip_tests_and_comments(text: str) -> str:
    text = re.sub(r"//[^\n]*", "", text)
    # drop `#[cfg(test)] mod tests { ... }` blocks (brace matching)
    out, i = [], 0
    for m in re.finditer(r"#\[cfg\(test\)\]\s*(pub(\([a-z]+\))?\s+)?mod\s+\w+\s*\{", text):
        if m.start() < i:
            continue
        out.append(text[i : m.start()])
        depth, j = 1, m.end()
        while j < len(text) and depth:
            depth += {"{": 1, "}": -1}.get(text[j], 0)
            j += 1
        i = j
    out.append(text[i:])
    return "".join(out)


def resolve(modules, base, segs):
    """Deepest existing module reached by `base` + `segs`."""
    best = None
    cur = list(base)
    if cur in ([],) or tuple(cur) in modules:
        best = tuple(cur)
    for s in segs:
        cur.append(s)
        if tuple(cur) in modules:
            best = tuple(cur)
    return best


def crate_edges(crate: pathlib.Path):
    src = crate / "src"
    files = sorted(p for p in src.rglob("*.rs"))
    modules = {module_of(src, f): f for f in files}
    edges = {m: set() for m in modules}
    for m, f in modules.items():
        text = strip_tests_and_comments(f.read_text())
        # expand `use a::b::{c, d::e}` into paths
        paths = []
        for g in USE_GROUP_RE.finditer(text):
            head = g.group(2).strip(":").split("::") if g.group(2) else []
            for item in re.split(r",", g.group(3)):
                item = item.strip().split(" as ")[0].strip()
                if not item or item.startswith("{"):
                    continue
                paths.append((g.group(1), head + [s for s in item.split("::") if s]))
        for p in PATH_RE.finditer(text):
            paths.append((p.group(1), [s for s in p.group(2).split("::") if s]))
        is_dir_module = f.name in ("mod.rs", "lib.rs", "main.rs")
        for kind, segs in paths:
            if kind == "crate":
                base = []
            elif kind == "self":
                base = list(m)
            else:  # super: the parent of this module (a mod.rs is its directory's module)
                base = list(m[:-1])
                while segs and segs[0] == "super":
                    base, segs = base[:-1], segs[1:]
            target = resolve(modules, base, segs)
            if target is not None and target != m:
                # a module using its own child is structure, not a layering arrow
                if is_dir_module and target[: len(m)] == m:
                    continue
                edges[m].add(target)
    return modules, edges


def sccs(edges):
    index, low, stack, on, out, n = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = n[0]
        n[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in list(edges):
        if v not in index:
            visit(v)
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--allow", type=int, default=0)
    args = ap.parse_args()
    total = 0
    for crate in sorted((ROOT / "crates").iterdir()):
        if not (crate / "src").is_dir():
            continue
        modules, edges = crate_edges(crate)
        for comp in sccs(edges):
            total += 1
            names = ["::".join(c) or "(root)" for c in comp]
            print(f"{crate.name}: {' <-> '.join(names)}")
    print(f"{total} import cycle(s) between files")
    sys.exit(1 if total > args.allow else 0)


if __name__ == "__main__":
    main()
