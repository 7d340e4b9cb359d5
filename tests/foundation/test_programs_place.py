"""The programs a user runs come from one place, build/bin, after tools/demo or tools/test.

tools/lib.sh's link_programs runs on a copy of the tools in a scratch tree whose build/asan
and build/release hold stand-in programs (empty scripts named as the real ones; nothing is
built here): build/bin must link every autodrive-* program and nano-simavr, the release one
where both exist. tools/demo, tools/test and tools/build must call it, and the README and the
guides must name build/bin, never a preset's own bin folder.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest


@pytest.fixture
def root() -> Path:
    return Path(os.environ.get("AUTODRIVE_ROOT", Path(__file__).resolve().parents[2]))


def make_program(path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("#!/bin/sh\n")
    path.chmod(0o755)


@pytest.mark.parametrize(
    "command",
    [
        "source {tree}/tools/lib.sh && link_programs",
        # the Jetson guide's native build (plain cmake) links with this; nothing set up or built
        "{tree}/tools/build --link-only",
    ],
)
def test_link_programs_prefers_release(root: Path, tmp_path: Path, command: str) -> None:
    shutil.copytree(root / "tools", tmp_path / "tools", symlinks=True)
    for name in ("autodrive-sim", "autodrive-eye", "nano-simavr", "runtime_unit_tests"):
        make_program(tmp_path / "build" / "asan" / "bin" / name)
    make_program(tmp_path / "build" / "release" / "bin" / "autodrive-sim")
    r = subprocess.run(
        ["bash", "-c", command.format(tree=tmp_path)],
        capture_output=True,
        text=True,
        check=True,
    )
    print(r.stdout)
    out = tmp_path / "build" / "bin"
    assert sorted(p.name for p in out.iterdir()) == [
        "autodrive-eye",
        "autodrive-sim",
        "nano-simavr",
    ]
    assert os.readlink(out / "autodrive-sim") == "../release/bin/autodrive-sim"
    assert os.readlink(out / "autodrive-eye") == "../asan/bin/autodrive-eye"
    assert (out / "nano-simavr").resolve() == tmp_path / "build" / "asan" / "bin" / "nano-simavr"


@pytest.mark.parametrize("tool", ["demo", "test", "build"])
def test_every_build_command_links_programs(root: Path, tool: str) -> None:
    text = (root / "tools" / tool).read_text()
    assert re.search(r"^link_programs$", text, re.M), f"tools/{tool} does not call link_programs"


def test_guides_name_build_bin(root: Path) -> None:
    pages = [root / "README.md", root / "docs" / "getting-started.md"]
    pages += sorted((root / "docs" / "guides").glob("*.md"))
    pages += sorted((root / "tools" / "systemd").glob("*.service"))  # what runs on the car
    bad = [
        f"{p.relative_to(root)}:{i}: {line.strip()}"
        for p in pages
        for i, line in enumerate(p.read_text().splitlines(), 1)
        if re.search(r"build/(release|asan|dev)/bin/", line)
    ]
    assert not bad, "user commands must run programs from build/bin:\n" + "\n".join(bad)


def test_jetson_native_build_links_programs(root: Path) -> None:
    # The Jetson guide builds with plain cmake (no tools/setup there) and then runs build/bin.
    guide = (root / "docs" / "guides" / "jetson.md").read_text()
    build = guide.index("cmake --build build/release")
    assert (
        "tools/build --link-only" in guide[build : guide.index("```", build)]
    ), "docs/guides/jetson.md: the native build must link its programs into build/bin"
