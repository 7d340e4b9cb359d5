"""A real Ray cluster on loopback for tests (pyhelpers.ray_cluster): `ray start --head` plus nodes joining it, each with
its CPUs, in one temp dir; stopped bounded in time, its processes found by that temp dir so that
nothing else on the machine that runs Ray is touched. Used by sweep.ray_cluster_parking and
marl.ray_train."""

from __future__ import annotations

import os
import pathlib
import signal
import socket
import subprocess
import time

ENV = dict(os.environ, RAY_USAGE_STATS_ENABLED="0")


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port: int = s.getsockname()[1]
        return port


def ours(tmp: str) -> list[int]:
    """Pids of the processes of this cluster: their command line names its temp dir."""
    pids = []
    for d in pathlib.Path("/proc").iterdir():
        if d.name.isdigit() and int(d.name) != os.getpid():
            try:
                if tmp.encode() in (d / "cmdline").read_bytes():
                    pids.append(int(d.name))
            except OSError:
                pass
    return pids


def start_cluster(
    ray: pathlib.Path, tmp: str, cpus: list[int], nodes: list[subprocess.Popen[bytes]]
) -> str:
    """Starts a head and len(cpus) - 1 joining nodes (node i with cpus[i] CPUs), appending each
    `ray start --block` to nodes as it starts (so that a caller's finally stops them even when
    this fails); waits for each node (<= 300 s: `ray status` is slow on a loaded machine). Returns the address HOST:PORT.
    """
    gcs = free_port()
    address = f"127.0.0.1:{gcs}"
    total = 0
    for i, n_cpus in enumerate(cpus):
        common = ["--num-cpus", str(n_cpus), "--node-ip-address", "127.0.0.1", "--block"]
        common += ["--disable-usage-stats", "--object-store-memory", str(200 * 1024 * 1024)]
        if i == 0:
            argv = [str(ray), "start", "--head", "--port", str(gcs), "--temp-dir", tmp]
            argv += ["--include-dashboard=false", "--ray-client-server-port", str(free_port())]
        else:
            argv = [str(ray), "start", "--address", address]
        argv += ["--dashboard-agent-listen-port", str(free_port())]
        argv += ["--dashboard-agent-grpc-port", str(free_port())]
        argv += ["--metrics-export-port", str(free_port())]
        log = open(pathlib.Path(tmp) / f"node{i}.log", "wb")
        nodes.append(subprocess.Popen(argv + common, stdout=log, stderr=log, env=ENV))
        total += n_cpus
        # the head first: the next node joins it
        probe = [str(ray), "status", "--address", address]
        deadline = time.monotonic() + 300
        while True:
            assert nodes[-1].poll() is None, f"ray start exited: see {log.name}"
            try:
                st = subprocess.run(probe, capture_output=True, text=True, env=ENV, timeout=60)
                if st.returncode == 0 and f"0.0/{total}.0 CPU" in st.stdout:
                    break
                seen = st.stdout + st.stderr
            except subprocess.TimeoutExpired:
                seen = "`ray status` took over 60 s"
            assert time.monotonic() < deadline, f"node {i} not up: {seen}"
            time.sleep(1.0)
    return address


def stop_cluster(nodes: list[subprocess.Popen[bytes]], tmp: str) -> None:
    """SIGTERM to each `ray start --block` (it stops its node), then SIGKILL what is left of
    this cluster; at most ~30 s."""
    for n in nodes:
        if n.poll() is None:
            n.send_signal(signal.SIGTERM)
    deadline = time.monotonic() + 20
    for n in nodes:
        try:
            n.wait(timeout=max(0.1, deadline - time.monotonic()))
        except subprocess.TimeoutExpired:
            n.kill()
            n.wait(timeout=5)
    for _ in range(10):
        left = ours(tmp)
        if not left:
            return
        for pid in left:
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        time.sleep(0.5)
    raise AssertionError(f"cluster processes still alive after the stop: {ours(tmp)}")
