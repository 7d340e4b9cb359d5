"""Child processes: the one process stopper (SIGINT, then SIGTERM, then SIGKILL) and a group
runner that starts named programs with their own log files and stops them in reverse order,
handing back each child's exit code and any sanitizer report (ASan, UBSan, LSan) in its log, so
that a report at shutdown fails the test or mission that ran it."""

from __future__ import annotations

import ctypes
import os
import resource
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

# How long a child gets to act on SIGINT (flush its log, publish its last command), then on
# SIGTERM, before SIGKILL.
SIGINT_GRACE_S = 5.0
SIGTERM_GRACE_S = 3.0

# What a child gets when the process that started it dies (SIGKILL, SIGHUP, a crash: no
# `finally` of ours runs then, and a child in its own session hears no terminal signal).
PARENT_DEATH_SIGNAL = signal.SIGTERM
_PR_SET_PDEATHSIG = 1  # <linux/prctl.h>

Log = Callable[[str], None]
# The first line of a sanitizer's report (gcc's ASan/LSan/UBSan runtimes)
SANITIZER_MARKS = ("ERROR: AddressSanitizer", "ERROR: LeakSanitizer", "runtime error:",
                   "SUMMARY: UndefinedBehaviorSanitizer")  # fmt: skip
REPORT_LINES = 12  # of a report kept in the result


def sanitizer_report(logfile: Path) -> str | None:
    """The first sanitizer report in a child's log (its first REPORT_LINES lines), or None."""
    try:
        lines = logfile.read_text(errors="replace").splitlines()
    except OSError:
        return None
    for k, line in enumerate(lines):
        if any(m in line for m in SANITIZER_MARKS):
            return "\n".join(lines[k : k + REPORT_LINES])
    return None


@dataclass(frozen=True)
class ChildExit:
    """How a child of a ProcessGroup ended: its exit code (< 0: the signal that ended it),
    whether it had to be killed, and the sanitizer report in its log (None: none)."""

    name: str
    exit_code: int
    killed: bool
    log: str
    sanitizer_report: str | None

    def as_dict(self) -> dict[str, Any]:
        return {"name": self.name, "exit_code": self.exit_code, "killed": self.killed,
                "log": self.log, "sanitizer_report": self.sanitizer_report}  # fmt: skip


def sanitizer_failures(exits: Sequence[ChildExit]) -> list[str]:
    """One line per child whose log holds a sanitizer report ([] = clean)."""
    return [
        f"{e.name}: sanitizer report in {e.log}: {(e.sanitizer_report or '').splitlines()[0]}"
        for e in exits
        if e.sanitizer_report
    ]


def third_party_env() -> dict[str, str]:
    """This process's environment without LD_PRELOAD, for a third-party program (a compiler, a
    database, a browser, a JVM): a sanitized test preloads the ASan runtime only for the processes
    that load our cffi libraries, and under it these hang, exit at start or report their own leaks.
    tools/lib.sh's build_host applies the same rule to the compilers (env -u LD_PRELOAD)."""
    return {k: v for k, v in os.environ.items() if k != "LD_PRELOAD"}


def die_with_parent() -> Callable[[], None] | None:
    """A preexec_fn that has the kernel send PARENT_DEATH_SIGNAL to the child when the thread
    that started it ends (Linux prctl PR_SET_PDEATHSIG). Everything it calls is bound here, in
    the parent: between fork and exec the child only makes the system calls. None (no such
    call) on other systems."""
    if not sys.platform.startswith("linux"):
        return None
    prctl = ctypes.CDLL(None, use_errno=True).prctl
    parent = os.getpid()
    sig = int(PARENT_DEATH_SIGNAL)

    def preexec() -> None:
        if prctl(_PR_SET_PDEATHSIG, sig, 0, 0, 0) != 0:
            raise OSError(ctypes.get_errno(), "prctl(PR_SET_PDEATHSIG)")
        if os.getppid() != parent:  # the parent died before prctl: nobody would stop us
            os.kill(os.getpid(), sig)

    return preexec


def stop(
    proc: subprocess.Popen[Any],
    name: str,
    log: Log,
    sigint_grace_s: float = SIGINT_GRACE_S,
    sigterm_grace_s: float = SIGTERM_GRACE_S,
) -> int:
    """Stops proc (SIGINT, SIGTERM, SIGKILL, each after its grace time); returns its exit code."""
    for sig, grace_s in ((signal.SIGINT, sigint_grace_s), (signal.SIGTERM, sigterm_grace_s)):
        if proc.poll() is not None:
            return proc.returncode
        proc.send_signal(sig)
        try:
            return proc.wait(timeout=grace_s)
        except subprocess.TimeoutExpired:
            log(f"{name} did not stop on {sig.name} within {grace_s:g} s")
    log(f"killing {name}")
    proc.kill()
    return proc.wait()


class ProcessGroup:
    """Named child processes, each in its own session (a Ctrl-C on the terminal reaches only
    us, and we stop them in order), stdout and stderr into one log file each. On Linux each
    child also gets PARENT_DEATH_SIGNAL when the thread that started it ends, so that no child
    outlives a parent that died without stopping it (start them from a thread that lives as
    long as they should)."""

    def __init__(self, log: Log) -> None:
        self.log = log
        self.items: list[tuple[str, subprocess.Popen[bytes], IO[str]]] = []

    def start(self, name: str, argv: Sequence[object], logfile: Path) -> subprocess.Popen[bytes]:
        self.log(f"starting {name}: {' '.join(map(str, argv))}")
        f = open(logfile, "w")
        proc = subprocess.Popen(
            [str(a) for a in argv],
            stdout=f,
            stderr=subprocess.STDOUT,
            start_new_session=True,
            preexec_fn=die_with_parent(),
        )
        self.items.append((name, proc, f))
        return proc

    def check(self, besides: str | None = None, clean_exit_fails: bool = False) -> None:
        """Raises RuntimeError when a child (other than `besides`) has exited with an error, or
        at all with clean_exit_fails (a service that must outlive the mission)."""
        for name, proc, f in self.items:
            if name == besides:
                continue
            code = proc.poll()
            if code is not None and (code != 0 or clean_exit_fails):
                raise RuntimeError(f"{name} exited with code {code} (log: {f.name})")

    def stop_all(self) -> list[ChildExit]:
        """Stops every child, the last started first; how each ended, in start order."""
        exits = []
        for name, proc, f in reversed(self.items):
            notes: list[str] = []

            def note(msg: str) -> None:
                notes.append(msg)
                self.log(msg)

            code = stop(proc, name, note)
            f.close()
            report = sanitizer_report(Path(f.name))
            if report:
                self.log(f"{name}: sanitizer report in {f.name}")
            was_killed = any(m.startswith("killing") for m in notes)
            exits.append(ChildExit(name, code, was_killed, f.name, report))
        self.items.clear()
        return exits[::-1]

    def stop_all_checked(self) -> list[ChildExit]:
        """stop_all, raising RuntimeError when a child's log holds a sanitizer report (for
        tests: a report at shutdown fails them)."""
        exits = self.stop_all()
        bad = sanitizer_failures(exits)
        if bad:
            raise RuntimeError("; ".join(bad))
        return exits


def wait_for_path(path: Path, timeout_s: float, procs: ProcessGroup) -> None:
    """Waits until path exists (a pty a child creates), failing early if a child died."""
    t0 = time.monotonic()
    while not os.path.exists(path):
        procs.check()
        if time.monotonic() - t0 > timeout_s:
            raise RuntimeError(f"{path} did not appear within {timeout_s} s")
        time.sleep(0.05)


def cpu_time_s(pid: int) -> float:
    """CPU time [s] a process has used (user + system, with its children it waited for), from
    /proc; 0 when it is gone."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return 0.0
    fields = stat.rsplit(")", 1)[1].split()  # after the command name: field 3 (state) first
    ticks = sum(int(f) for f in fields[11:15])  # utime, stime, cutime, cstime (fields 14-17)
    return ticks / os.sysconf("SC_CLK_TCK")


def wait_ready(
    name: str,
    proc: subprocess.Popen[bytes],
    probe: Callable[[], str | None],
    procs: ProcessGroup,
    cpu_budget_s: float,
    wall_limit_s: float,
    log: Log,
    logfile: Path,
) -> float:
    """Waits until probe() answers None (ready; else it says what it saw). A start on a loaded
    machine takes what the CPU gives it, so the limit is the child's own CPU time: it fails
    when the child used cpu_budget_s of CPU without becoming ready, or exited, or (a hang
    guard) after wall_limit_s. Returns the CPU time the start took [s]."""
    t0 = time.monotonic()
    next_note = t0 + 15.0
    why = "no answer yet"

    def log_end() -> str:
        try:
            tail = logfile.read_text(errors="replace").splitlines()[-5:]
        except OSError:
            tail = []
        return f"the end of {logfile}: {' | '.join(tail) or '(empty)'}"

    while True:
        try:
            procs.check()
        except RuntimeError as err:  # a child died: say what its log says
            raise RuntimeError(f"waiting for {name} to be ready: {err}; {log_end()}") from err
        answer = probe()
        if answer is None:
            return cpu_time_s(proc.pid)
        why = answer
        cpu = cpu_time_s(proc.pid)
        wall = time.monotonic() - t0
        load = os.getloadavg()[0]
        if cpu > cpu_budget_s or wall > wall_limit_s:
            limit = (
                f"{cpu_budget_s:g} s of its CPU time" if cpu > cpu_budget_s
                else f"the {wall_limit_s:g} s wall-time guard"
            )  # fmt: skip
            raise RuntimeError(
                f"{name} not ready within {limit} (it used {cpu:.1f} s of CPU in {wall:.0f} s "
                f"wall, load average {load:.1f} on {os.cpu_count()} cores); last probe: {why}; "
                f"{log_end()}"
            )
        if time.monotonic() >= next_note:
            next_note += 15.0
            log(f"waiting for {name}: {cpu:.1f} s CPU, {wall:.0f} s wall, load {load:.1f} ({why})")
        time.sleep(0.2)


def cpu_s() -> float:
    """CPU time [s] (user + system) of this process and every finished child process and their
    children: a pipeline's own cost, whatever else loads the machine."""
    rs = (resource.getrusage(w) for w in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN))
    return sum(r.ru_utime + r.ru_stime for r in rs)
