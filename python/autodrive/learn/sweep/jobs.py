"""Independent jobs on Ray, for tools/sweep and tools/bench: a job is a picklable module-level
function and its argument; results come back in the order of the jobs, whatever node ran them
and in whatever order they finished. Ray runs embedded and local (`workers` CPUs, a private temp
dir removed afterwards) unless an address joins an existing cluster (`ray start --head` on one
machine, `ray start --address HEAD:PORT` on the others). Without Ray (serial), the same
functions run one after the other in this process: the reference a Ray run must agree with."""

from __future__ import annotations

import logging
import os
import shutil
import signal
import socket
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

# No usage statistics to the network, from this driver nor from the workers it starts.
os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")

A = TypeVar("A")
R = TypeVar("R")
# A local Ray's object store [bytes]: jobs return small files and figures, not frames.
LOCAL_OBJECT_STORE_BYTES = 256 * 1024 * 1024


@dataclass
class Pool:
    """Where jobs run: None = serially in this process, else the Ray cluster it joined."""

    address: str | None
    workers: int
    serial: bool
    temp_dir: str | None = None
    cluster_cpus: float = 0.0
    init_s: float = 0.0

    def describe(self) -> str:
        if self.serial:
            return "serially in this process (no Ray)"
        if self.address is None:
            return f"embedded local Ray, {self.workers} worker(s)"
        return f"Ray cluster at {self.address} ({self.cluster_cpus:g} CPUs)"


def open_pool(workers: int, address: str | None, serial: bool = False) -> Pool:
    """Starts (workers CPUs) or joins (address) Ray; serial: no Ray. ValueError on bad input,
    RuntimeError when the cluster cannot be reached."""
    if workers < 1:
        raise ValueError(f"--workers {workers}: need at least 1 worker")
    if serial and address:
        raise ValueError(f"--address {address} and --serial: choose one")
    pool = Pool(address, workers, serial)
    if serial:
        return pool
    import ray  # here, not at import: serial runs and --help need no Ray

    t0 = time.monotonic()
    try:
        if address is None:
            # Short path: Ray's unix sockets live under it (108 bytes at most).
            pool.temp_dir = tempfile.mkdtemp(prefix="adray-", dir="/tmp")
            ray.init(
                num_cpus=workers,
                include_dashboard=False,
                object_store_memory=LOCAL_OBJECT_STORE_BYTES,
                _temp_dir=pool.temp_dir,
                logging_level=logging.WARNING,
                log_to_driver=False,
            )
        else:
            _reachable(address)  # Ray itself would retry for minutes
            ray.init(address=address, logging_level=logging.WARNING, log_to_driver=False)
    except (ConnectionError, RuntimeError, ValueError) as e:
        close_pool(pool)
        where = address or "a local Ray"
        raise RuntimeError(f"--address {where}: cannot start or join Ray ({e})") from None
    pool.cluster_cpus = float(ray.cluster_resources().get("CPU", 0.0))
    pool.init_s = time.monotonic() - t0
    return pool


def _reachable(address: str, timeout_s: float = 5.0) -> None:
    """ConnectionError naming the address unless its HOST:PORT accepts a TCP connection."""
    host, sep, port = address.rpartition(":")
    if not sep or not host or not port.isdigit():
        raise ValueError("want HOST:PORT, the address `ray start --head` printed")
    try:
        socket.create_connection((host, int(port)), timeout=timeout_s).close()
    except OSError as e:
        raise ConnectionError(f"no Ray head answers there ({e})") from None


def close_pool(pool: Pool) -> None:
    """Leaves the cluster (a local one stops) and removes the local Ray's temp dir."""
    if pool.serial:
        return
    import ray

    if ray.is_initialized():
        ray.shutdown()
    if pool.temp_dir:
        shutil.rmtree(pool.temp_dir, ignore_errors=True)


def where() -> str:
    """This process's place: the host name, and on Ray "host:node" (8 hex digits of the Ray
    node id: several nodes may share a host)."""
    ray = sys.modules.get("ray")  # never imported here for a serial run
    if ray is not None and ray.is_initialized():
        return f"{socket.gethostname()}:{ray.get_runtime_context().get_node_id()[:8]}"
    return socket.gethostname()


def _on_node(fn: Callable[[A], R], arg: A) -> tuple[R, str, float]:
    """Runs one job where Ray put it: (its result, where(), its wall time [s]). A Ray worker
    blocks SIGINT, and the programs a job starts would inherit that mask and ignore the SIGINT
    that asks them to stop cleanly: unblocked while the job runs."""
    t0 = time.monotonic()
    mask = signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT, signal.SIGTERM})
    try:
        result = fn(arg)
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, mask)
    return result, where(), time.monotonic() - t0


def run_jobs(
    pool: Pool,
    fn: Callable[[A], R],
    args: Sequence[A],
    done: Callable[[int, R, str, float], None],
    cpus_per_job: float = 1.0,
) -> list[R]:
    """fn(arg) for every arg, on the pool; done(index, result, host, wall_s) as each finishes
    (on the driver, in finishing order). Returns the results in the order of args. A
    KeyboardInterrupt cancels the jobs still running (each gets a KeyboardInterrupt, so a job
    that runs processes can stop them) and propagates."""
    if pool.serial:
        results: list[R] = []
        for i, arg in enumerate(args):
            r, host, wall_s = _on_node(fn, arg)
            done(i, r, host, wall_s)
            results.append(r)
        return results
    import ray

    remote: Any = ray.remote(num_cpus=cpus_per_job, max_retries=0)(_on_node)
    refs = [remote.remote(fn, arg) for arg in args]
    index = {ref: i for i, ref in enumerate(refs)}
    out: dict[int, R] = {}
    pending = list(refs)
    try:
        while pending:
            ready, pending = ray.wait(pending, num_returns=1)
            for ref in ready:
                r, host, wall_s = ray.get(ref)
                out[index[ref]] = r
                done(index[ref], r, host, wall_s)
    except BaseException:
        for ref in pending:
            ray.cancel(ref, force=False)
        raise
    return [out[i] for i in range(len(args))]
