#!/usr/bin/env python3
"""Checks a built documentation site (mdBook's HTML output) for broken internal links, missing
anchors and missing images.

    mdbook build docs && python3 scripts/check_docs.py docs/book

Every `href` and `src` in every page that is not an external URL must name a file of the site;
a `#fragment` on a link to a page must name an element id of that page. Exits 1 naming each
broken reference (page, target), so CI fails on the first drift.
"""

import html.parser
import pathlib
import sys
import urllib.parse

EXTERNAL = ("http://", "https://", "mailto:", "data:", "javascript:")


class Page(html.parser.HTMLParser):
    def __init__(self):
        super().__init__()
        self.refs, self.ids = [], set()

    def handle_starttag(self, tag, attrs):
        for name, value in attrs:
            if name == "id" and value:
                self.ids.add(value)
            if name in ("href", "src") and value and tag in ("a", "img", "script", "link"):
                self.refs.append((tag, value))


def parse(path, cache):
    if path not in cache:
        page = Page()
        page.feed(path.read_text(encoding="utf-8", errors="replace"))
        cache[path] = page
    return cache[path]


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    root = pathlib.Path(sys.argv[1]).resolve()
    if not (root / "index.html").is_file():
        sys.exit(f"{root}: no index.html; build the book first (mdbook build docs)")
    cache, broken, checked = {}, [], 0
    for page_path in sorted(root.rglob("*.html")):
        page = parse(page_path, cache)
        for tag, ref in page.refs:
            if ref.startswith(EXTERNAL) or ref.startswith("#") and tag != "a":
                continue
            url = urllib.parse.urlsplit(ref)
            if url.scheme or url.netloc:
                continue
            checked += 1
            target = (
                page_path
                if not url.path
                else (page_path.parent / urllib.parse.unquote(url.path)).resolve()
            )
            where = page_path.relative_to(root)
            if target.is_dir():
                target = target / "index.html"
            if root not in target.parents and target != root:
                broken.append(f"{where}: {ref} points outside the site")
                continue
            if not target.is_file():
                broken.append(f"{where}: {ref} ({tag}) does not exist")
                continue
            if url.fragment and target.suffix == ".html":
                if urllib.parse.unquote(url.fragment) not in parse(target, cache).ids:
                    broken.append(f"{where}: {ref} names no anchor of that page")
    for b in broken:
        print(b)
    print(f"check_docs: {checked} internal references in {len(cache)} pages, {len(broken)} broken")
    sys.exit(1 if broken else 0)


if __name__ == "__main__":
    main()
