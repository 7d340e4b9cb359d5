"""A private ROS master for a test or bench: `roscore -p PORT` with its logs in a temp ROS_HOME,
and the environment (ROS_MASTER_URI, ROS_HOME) that its ROS children and this process use."""

from __future__ import annotations

import os
import shutil
import socket
import time
from pathlib import Path

from autodrive.core.proc import ProcessGroup

MASTER_WAIT_S = 60.0  # a guard: roscore's start is CPU-bound on a loaded machine


def free_tcp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def start(procs: ProcessGroup, work: Path) -> str:
    """Starts roscore in procs, points this process's environment at it, waits until it answers;
    returns its URI. RuntimeError naming what is missing or what failed."""
    if shutil.which("roscore") is None:
        raise RuntimeError("roscore not found: install Debian's ros-core (tools/setup does)")
    port = free_tcp_port()
    uri = f"http://127.0.0.1:{port}"
    os.environ["ROS_MASTER_URI"] = uri
    os.environ["ROS_HOME"] = str(work / "ros_home")
    os.environ.setdefault("ROS_IP", "127.0.0.1")
    procs.start("roscore", ["roscore", "-p", port], work / "roscore.log")
    import rosgraph  # Debian's python3-rosgraph (with rospy)

    t0 = time.monotonic()
    while not rosgraph.is_master_online(uri):
        procs.check()
        if time.monotonic() - t0 > MASTER_WAIT_S:
            raise RuntimeError(f"roscore on {uri} did not answer within {MASTER_WAIT_S:g} s")
        time.sleep(0.2)
    return uri
