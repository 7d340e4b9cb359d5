"""HIL: the demo's Python killed (SIGKILL: no `finally` of its own runs) right after it started
lcm-logger and the simulator. Its children live in sessions of their own, so no terminal
signal reaches them: the kernel's parent-death signal (autodrive.core.proc, PR_SET_PDEATHSIG)
must stop every one of them. Nothing is timed: the test waits for the demo's own progress line,
then for each child's exit (a pidfd; ctest's timeout is the hang guard)."""
import os
import select
import signal
import subprocess
import tempfile

from hil_demo import start_demo_until


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
        # "starting autodrive-sim": lcm-logger runs, the simulator is starting
        marker = "starting autodrive-sim"
        demo, seen = start_demo_until(build_dir, tmp, lcm_port, marker, "--timeout", "200")
        assert demo.poll() is None, "the demo ended before it started:\n" + "".join(seen)
        children = children_of_run(tmp)
        assert children, "lcm-logger is not running:\n" + "".join(seen)
        demo.send_signal(signal.SIGKILL)
        demo.wait()
        demo.stdout.close()
        for pid in children + children_of_run(tmp):
            wait_gone(pid)
        assert not children_of_run(tmp), "children left behind"
