"""HIL: the demo's Python killed (SIGKILL: no `finally` of its own runs) right after it started
lcm-logger and the simulator. Its children live in sessions of their own, so no terminal
signal reaches them: the kernel's parent-death signal (autodrive.core.proc, PR_SET_PDEATHSIG)
must stop every one of them. Nothing is timed: the test waits for the demo's own progress line,
then for each child's exit (a pidfd; ctest's timeout is the hang guard)."""
import os
import select
import signal
import subprocess
import sys
import tempfile

from hil_demo import demo_command


def children_of_run(tmp: str) -> list[int]:
    """Processes whose command line names the run's folder (lcm-logger writes its log there)."""
    r = subprocess.run(["pgrep", "-f", tmp], capture_output=True, text=True)
    return [int(p) for p in r.stdout.split() if p]


def wait_gone(pid: int) -> None:
    try:
        fd = os.pidfd_open(pid)
    except ProcessLookupError:
        return  # already gone
    try:
        poller = select.poll()
        poller.register(fd, select.POLLIN)
        poller.poll()  # readable once the process has exited
    finally:
        os.close(fd)


def test_killed_demo_leaves_no_child(build_dir, lcm_port) -> None:
    with tempfile.TemporaryDirectory(prefix="hil-dies-") as tmp:
        demo = subprocess.Popen(
            demo_command(build_dir, tmp, lcm_port, "--timeout", "200"),
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        seen = []
        for line in demo.stdout:
            seen.append(line)
            sys.stdout.write(line)
            if "starting autodrive-sim" in line:  # lcm-logger runs, the simulator is starting
                break
        assert demo.poll() is None, "the demo ended before it started:\n" + "".join(seen)
        children = children_of_run(tmp)
        assert children, "lcm-logger is not running:\n" + "".join(seen)
        demo.send_signal(signal.SIGKILL)
        demo.wait()
        demo.stdout.close()
        for pid in children + children_of_run(tmp):
            wait_gone(pid)
        assert not children_of_run(tmp), "children left behind"
