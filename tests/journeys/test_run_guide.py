"""The journey doc-test runner (run_guide.py) on small guides written here: marked blocks run
in order in one shell (a variable and a background job of one step are there in the next), an
unmarked block never runs, a failing command fails its step and names it, a stuck step is
stopped by its guard, a mark without a block is an error, and every process a guide started is
gone afterwards. Nothing here judges how long a step took: the guard is a hang guard."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

RUNNER = Path(__file__).with_name("run_guide.py")


def run(tmp: Path, text: str) -> subprocess.CompletedProcess[str]:
    guide = tmp / "guide.markdown"
    guide.write_text(text)
    return subprocess.run(
        [sys.executable, str(RUNNER), str(guide), "--root", str(tmp), "--build", str(tmp),
         "--instance", "40"],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip


def test_steps_share_one_shell_and_skip_unmarked(tmp_path: Path) -> None:
    r = run(
        tmp_path,
        "# A guide\n\n<!-- ci-run -->\n```sh\nX=41\nsleep 600 &\necho $! > bg.pid\n```\n\n"
        "```sh\ntouch never-run\n```\n\n<!-- ci-run timeout=30 -->\n```sh\n"
        'test "$X" = 41 && echo "instance $AUTODRIVE_INSTANCE" && printf no-newline\n```\n',
    )
    print(r.stdout, r.stderr)
    assert r.returncode == 0, r.stderr
    assert (
        "instance 40" in r.stdout
        and "no-newline" in r.stdout
        and "ok: guide.markdown: 2 steps" in r.stdout
    )
    assert not (tmp_path / "never-run").exists(), "an unmarked block ran"
    pid = int((tmp_path / "bg.pid").read_text())
    try:
        os.kill(pid, 0)
        alive = True
    except ProcessLookupError:
        alive = False
    assert not alive, "the guide's background job outlived it"


def test_failing_step_is_named(tmp_path: Path) -> None:
    r = run(
        tmp_path,
        "<!-- ci-run -->\n```sh\ntrue\n```\n<!-- ci-run -->\n```sh\nfalse\necho after\n```\n",
    )
    print(r.stdout, r.stderr)
    assert r.returncode == 1 and "guide.markdown:6: step 2 failed" in r.stderr
    assert "  after" not in r.stdout


def test_stuck_step_is_stopped_by_its_guard(tmp_path: Path) -> None:
    r = run(tmp_path, "<!-- ci-run timeout=2 -->\n```sh\nsleep 600\n```\n")
    assert r.returncode == 1 and "did not finish within its 2 s guard" in r.stderr, r.stderr


def test_mark_without_block_and_guide_without_marks(tmp_path: Path) -> None:
    r = run(tmp_path, "<!-- ci-run -->\ntext, not a block\n")
    assert r.returncode != 0 and "without a ```sh block" in r.stderr, r.stderr
    r = run(tmp_path, "```sh\necho hi\n```\n")
    assert r.returncode == 1 and "no ci-run blocks" in r.stderr, r.stderr
