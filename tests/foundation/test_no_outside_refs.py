"""foundation.no_outside_refs: no tracked file refers to anything outside the repository.

Fails on (1) a reference into a sibling "shared" folder, (2) an absolute path under a folder
that only exists on a developer's machine (/work, /home, /root, /Users, /mnt, /farm), (3) a
markdown link whose target is not in the tree, (4) a repo path ending in .md that is cited in
any file but does not exist, (5) a bare file name ending in .md that no tracked file has.
A self-check first plants each kind of violation in a scratch tree and requires it to be found.
"""

from __future__ import annotations

import os
import pathlib
import re
import subprocess
import tempfile

# Built from pieces so that this file does not match its own patterns.
SHARED = ".." + "/shared"
PRIVATE_ROOTS = ["work", "home", "root", "Users", "mnt", "farm"]
ABS_RE = re.compile(r"(?<![\w.~$}/-])/(?:" + "|".join(PRIVATE_ROOTS) + r")/[\w.-]")
MD_LINK_RE = re.compile(r"!?\[[^\]\n]*\]\(([^()\s]+)(?:\s+\"[^\"]*\")?\)")
MD_PATH_RE = re.compile(r"(?<![\w/.<>-])((?:[\w.-]+/)+[\w.-]+\.md)\b")
MD_NAME_RE = re.compile(r"(?<![\w/.-])([A-Za-z][\w-]*\.md)\b")
SKIP_DIRS = {".git", "build", ".venv", "out", "__pycache__", ".pio"}
TEXT_SUFFIXES_SKIPPED = {".png", ".jpg", ".jpeg", ".pgm", ".elf", ".hex", ".lcmlog", ".gz"}


def tracked_files(root: pathlib.Path) -> list[pathlib.Path]:
    """Files git tracks under root; every file outside SKIP_DIRS when root is not a checkout."""
    try:
        out = subprocess.run(
            ["git", "-C", str(root), "ls-files", "-z"],
            check=True,
            capture_output=True,
        ).stdout
        names = [n for n in out.decode().split("\0") if n]
        if names:
            return [root / n for n in names if (root / n).is_file()]
    except (OSError, subprocess.CalledProcessError):
        pass
    files = []
    for d, dirs, names in os.walk(root):
        dirs[:] = [x for x in dirs if x not in SKIP_DIRS]
        files += [pathlib.Path(d) / n for n in names]
    return files


def inside(root: pathlib.Path, p: pathlib.Path) -> bool:
    try:
        p.resolve().relative_to(root.resolve())
        return True
    except ValueError:
        return False


def check_tree(root: pathlib.Path) -> list[str]:
    """Every reference to something outside root (or missing from it), as 'file:line: why'."""
    files = tracked_files(root)
    basenames = {f.name for f in files}
    problems: list[str] = []
    for f in files:
        if f.suffix.lower() in TEXT_SUFFIXES_SKIPPED:
            continue
        try:
            text = f.read_text(encoding="utf-8")
        except (UnicodeDecodeError, OSError):
            continue  # binary
        rel = f.relative_to(root)
        is_md = f.suffix.lower() == ".md"
        for no, line in enumerate(text.splitlines(), 1):
            where = f"{rel}:{no}"
            if SHARED in line:
                problems.append(f"{where}: refers to {SHARED}, outside the repository")
            for m in ABS_RE.finditer(line):
                problems.append(f"{where}: absolute path outside the repository: {m.group(0)}...")
            if is_md:
                for m in MD_LINK_RE.finditer(line):
                    target = m.group(1)
                    if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith("#"):
                        continue  # URL, mailto:, in-page anchor
                    path = target.split("#", 1)[0]
                    dest = (root / path.lstrip("/")) if path.startswith("/") else f.parent / path
                    if not inside(root, dest):
                        problems.append(f"{where}: link '{target}' leaves the repository")
                    elif not dest.exists():
                        problems.append(f"{where}: link '{target}' has no target in the tree")
            for m in MD_PATH_RE.finditer(line):
                cited = m.group(1)
                if "<" in cited or "*" in cited:
                    continue
                candidates = [root / cited, f.parent / cited]
                if f.name == "mkdocs.yml":  # its nav names pages inside docs_dir
                    candidates.append(root / "docs" / cited)
                if not any(inside(root, c) and c.exists() for c in candidates):
                    problems.append(f"{where}: cites {cited}, which is not in the tree")
            for m in MD_NAME_RE.finditer(line):
                if m.group(1) not in basenames:
                    problems.append(f"{where}: cites {m.group(1)}, which no file is called")
    return problems


def self_check() -> list[str]:
    """Plants one violation of each kind and one clean file; returns what went undetected."""
    md = "." + "md"  # spelled in pieces: this file is scanned too
    missed: list[str] = []
    with tempfile.TemporaryDirectory() as tmp:
        t = pathlib.Path(tmp) / "repo"
        (t / "docs").mkdir(parents=True)
        (t / "docs" / f"GUIDE{md}").write_text(f"[ok](../README{md}) [web](https://x.org/a{md})\n")
        (t / f"README{md}").write_text(f"See [guide](docs/GUIDE{md}#top) and docs/GUIDE{md}.\n")
        clean = check_tree(t)
        if clean:
            missed.append(f"a clean tree was reported: {clean}")
        planted = {
            "a.c": f'#include "{SHARED}/x.h"\n',
            "b.sh": "cat /" + "work/main/notes.txt\n",
            f"c{md}": f"[gone](docs/MISSING{md})\n",
            f"d{md}": f"[out](../../elsewhere/README{md})\n",
            "e.txt": f"reference figures: docs/ARCH{md}\n",
            "f.h": f"/* see NOWHERE{md} */\n",
        }
        for name, body in planted.items():
            (t / name).write_text(body)
        found = check_tree(t)
        for name in planted:
            if not any(p.startswith(name + ":") for p in found):
                missed.append(f"planted violation in {name} not found")
    return missed


def test_self_check_finds_each_planted_violation() -> None:
    missed = self_check()
    assert not missed, "SELF-CHECK FAILED: " + "; ".join(missed)


def test_no_tracked_file_refers_outside(root: pathlib.Path) -> None:
    problems = check_tree(root.resolve())
    assert not problems, f"{len(problems)} reference(s) outside the tree:\n" + "\n".join(problems)
