"""Runs a guide's marked shell blocks, in order, as a user would type them (the journey doc tests).

A block runs when the line before its ```sh fence is `<!-- ci-run -->` (or `<!-- ci-run
timeout=S -->`, S: that step's hang guard [s wall], default 300). All blocks of a guide run in
one bash (`set -euo pipefail`), from the repository root, so a program started with `&` in one
step is there in the next, and what a step exports stays. A step fails when a command in it
fails, or when it has not finished within its hang guard (a stuck step, never a slow one: the
guards are far above what a step takes on a loaded machine). At the end every process the guide
started is stopped (its process group: SIGTERM, then SIGKILL).

The session is an instance of its own (AUTODRIVE_INSTANCE, from --instance), so the guide's
default LCM bus, web port and simulator run dir are nobody else's; AUTODRIVE_BUILD is the build
under test. Usage: run_guide.py GUIDE --root ROOT --build BUILD --instance N
"""

from __future__ import annotations

import argparse
import os
import re
import select
import signal
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

MARK = re.compile(r"^<!--\s*ci-run(?:\s+timeout=(\d+))?\s*-->\s*$")
FENCE_OPEN = re.compile(r"^```(sh|bash|console)?\s*$")
DEFAULT_TIMEOUT_S = 300
DONE = "__JOURNEY_STEP_DONE__"


@dataclass
class Step:
    line: int  # where the block starts in the guide (1-based)
    text: str
    timeout_s: int


def steps(guide: Path) -> list[Step]:
    """The marked blocks of a guide, in order."""
    lines = guide.read_text().splitlines()
    out: list[Step] = []
    i = 0
    while i < len(lines):
        m = MARK.match(lines[i])
        if m and i + 1 < len(lines) and FENCE_OPEN.match(lines[i + 1]):
            j = i + 2
            body = []
            while j < len(lines) and lines[j].strip() != "```":
                body.append(lines[j])
                j += 1
            if j == len(lines):
                raise ValueError(f"{guide}:{i + 2}: the marked block is never closed")
            out.append(Step(i + 2, "\n".join(body), int(m.group(1) or DEFAULT_TIMEOUT_S)))
            i = j
        elif m:
            raise ValueError(f"{guide}:{i + 1}: ci-run mark without a ```sh block after it")
        i += 1
    return out


class LineReader:
    """Lines of a pipe, waiting at most a while for each (os.read: nothing hides in a buffer
    that select() cannot see). "" once the pipe is closed."""

    def __init__(self, fd: int) -> None:
        self.fd, self.buf, self.closed = fd, b"", False

    def line(self, wait_s: float) -> str | None:
        while b"\n" not in self.buf and not self.closed:
            ready, _, _ = select.select([self.fd], [], [], wait_s)
            if not ready:
                return None
            chunk = os.read(self.fd, 65536)
            self.closed = not chunk
            self.buf += chunk
        if b"\n" in self.buf:
            line, self.buf = self.buf.split(b"\n", 1)
            return line.decode(errors="replace") + "\n"
        rest, self.buf = self.buf, b""
        return rest.decode(errors="replace")


def run(guide: Path, root: Path, env: dict[str, str]) -> int:
    todo = steps(guide)
    if not todo:
        print(f"{guide}: no ci-run blocks: nothing of this guide is checked", file=sys.stderr)
        return 1
    shell = subprocess.Popen(
        ["bash", "--noprofile", "--norc"],
        cwd=root,
        env=env,
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,
    )
    assert shell.stdin is not None and shell.stdout is not None
    reader = LineReader(shell.stdout.fileno())
    shell.stdin.write("set -euo pipefail\n")
    rc = 0
    try:
        for n, step in enumerate(todo, 1):
            print(f"--- step {n}/{len(todo)} ({guide.name}:{step.line}, guard {step.timeout_s} s)")
            print("\n".join(f"$ {ln}" for ln in step.text.splitlines()), flush=True)
            shell.stdin.write(f"{step.text}\necho {DONE} $?\n")
            shell.stdin.flush()
            end = time.monotonic() + step.timeout_s
            finished = eof = False
            while not finished and time.monotonic() < end:
                line = reader.line(1.0)
                if line is None:
                    continue
                if line == "":  # the shell exited: set -e on a failing command
                    eof = True
                    break
                before, done, _ = line.partition(DONE)  # output without a last newline
                if before.strip():
                    print(f"  {before.rstrip()}", flush=True)
                finished = bool(done)
            if not finished:
                # at the end of its output the shell may not be reaped yet: wait for it then
                why = (
                    f"failed (exit status {shell.wait(timeout=60)})"
                    if eof or shell.poll() is not None
                    else f"did not finish within its {step.timeout_s} s guard"
                )
                print(f"FAIL: {guide.name}:{step.line}: step {n} {why}", file=sys.stderr)
                rc = 1
                break
        if rc == 0:
            print(f"ok: {guide.name}: {len(todo)} steps")
    finally:
        stop_group(shell)
    return rc


def stop_group(shell: subprocess.Popen[str]) -> None:
    """Stops the guide's shell and everything it started (its own process group)."""
    for sig, wait_s in ((signal.SIGTERM, 10.0), (signal.SIGKILL, 5.0)):
        try:
            os.killpg(shell.pid, sig)
        except ProcessLookupError:
            return
        shell.poll()  # reap the shell itself, so the group can empty
        end = time.monotonic() + wait_s
        while time.monotonic() < end:
            try:
                os.killpg(shell.pid, 0)  # anyone of the group left?
            except ProcessLookupError:
                return
            time.sleep(0.1)
            shell.poll()


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("guide", type=Path)
    p.add_argument("--root", type=Path, required=True, help="the repository")
    p.add_argument("--build", type=Path, required=True, help="the build under test")
    p.add_argument("--instance", type=int, required=True, help="this run's AUTODRIVE_INSTANCE")
    a = p.parse_args(argv)
    env = dict(os.environ)
    env.update(
        AUTODRIVE_INSTANCE=str(a.instance),
        AUTODRIVE_BUILD=str(a.build.resolve()),
        AUTODRIVE_ROOT=str(a.root.resolve()),
    )
    return run(a.guide.resolve(), a.root.resolve(), env)


if __name__ == "__main__":
    sys.exit(main())
