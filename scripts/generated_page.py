"""The part of a documentation page below a marker line that a script writes: shared by
gen_cli_docs.py and gen_python_api.py."""

import pathlib
import sys


def write_below_marker(page: pathlib.Path, marker: str, body: str, check: bool, how: str):
    """Puts `body` below `marker` in `page`, or with `check` fails (naming `how` to fix it)
    when the page does not already say exactly that."""
    text = page.read_text(encoding="utf-8")
    if marker not in text:
        sys.exit(f"{page}: the marker line is missing:\n{marker}")
    new = text.split(marker)[0] + marker + "\n\n" + body
    if check:
        if new != text:
            sys.exit(f"{page} is out of date: run {how}")
        print(f"{page.name}: up to date")
    else:
        page.write_text(new, encoding="utf-8")
        print(f"wrote {page}")
