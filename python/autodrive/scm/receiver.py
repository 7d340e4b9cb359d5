"""The SCM's pose receiver, a process of its own: it reads every car's pose channels on LCM,
decodes them and hands them to the server in batches through a multiprocessing queue. In its
own process the socket is drained at once whatever the server's threads (database writer, web
API) are doing with the Python interpreter lock, so bursts are not dropped by the kernel."""

from __future__ import annotations

import multiprocessing as mp
import select
import time
from multiprocessing.synchronize import Event as EventType
from pathlib import Path
from typing import Any

from autodrive.core import channels, lcmtypes, v2x_auth
from autodrive.core.v2x_cert import CertificateError

# (source "eye"/"ekf", vehicle, utime [us], x [m], y [m], yaw [rad], speed [m/s] or None)
PoseTuple = tuple[str, str, int, float, float, float, float | None]
BATCH_S = 0.01
QUEUE_MESSAGES = 200_000  # per subscription: about 40 s of 100 cars at 50 Hz
RECV_BUF_BYTES = 4 << 20  # the socket's receive buffer (the kernel caps it at rmem_max)


def with_receive_buffer(url: str) -> str:
    """url with LCM's recv_buf_size option (unless it has one): a larger socket buffer rides
    out the moments this process does not get the CPU."""
    if not url.startswith("udpm://") or "recv_buf_size=" in url:
        return url
    return url + ("&" if "?" in url else "?") + f"recv_buf_size={RECV_BUF_BYTES}"


def run(build: str, url: str, pattern: str, out: "mp.Queue[list[PoseTuple]]",
        stop: EventType, ready: EventType, counters: Any) -> None:  # fmt: skip
    types = lcmtypes.load(Path(build))
    lc = lcmtypes.bus(with_receive_buffer(url))
    batch: list[PoseTuple] = []
    # Eye poses only from an eye certificate (a slow forged walk would move a car's lane and its
    # advisories): signature, role and a counter above that Eye's last. Their freshness is their
    # arrival on the server's clock (Car.seen_c), so the window is not checked here.
    verifier = v2x_auth.Verifier()
    eye_roles = v2x_auth.roles_for("POSE_EYE")
    drop_log = v2x_auth.DropLog()
    reload_at = 0.0

    def on_eye(chan: str, data: bytes) -> None:
        try:
            m = types.pose2d_t.decode(data)
        except Exception:  # a message that does not decode is counted, never believed
            counters[1] += 1
            return
        claimed = v2x_auth.sender_utime(v2x_auth.auth_of(m))
        verdict = verifier.verify(chan, m, eye_roles, None, m.utime if claimed is None else claimed)
        if not verdict.ok:
            counters[2] += 1
            drop_log.log(f"scm: {verdict.describe(chan)}", time.monotonic())
            return
        batch.append(("eye", chan.split("_", 1)[0], m.utime, m.x_m, m.y_m, m.yaw_rad, None))

    def on_ekf(chan: str, data: bytes) -> None:
        try:
            m = types.odometry_t.decode(data)
        except Exception:
            counters[1] += 1
            return
        batch.append(("ekf", chan.split("_", 1)[0], m.utime, m.x_m, m.y_m, m.yaw_rad, m.vx_m_s))

    table = channels.load()
    for cid, handler in (("POSE_EYE", on_eye), ("POSE_MAP", on_ekf)):
        sub = lc.subscribe(table.by_id(cid).name.replace(channels.VEH, pattern), handler)
        # LCM drops what a subscription has not handled beyond its queue (30 by default)
        sub.set_queue_capacity(QUEUE_MESSAGES)
    fd = lc.fileno()
    ready.set()
    flush_at = time.monotonic() + BATCH_S
    while not stop.is_set():
        if time.monotonic() >= reload_at:  # the revocation list (a stat), 4 times a second
            reload_at = time.monotonic() + 0.25
            try:
                verifier.reload()
            except (OSError, CertificateError) as err:
                drop_log.log(f"scm: revocation list: {err} (the list held so far stays)",
                             time.monotonic())  # fmt: skip
        if select.select([fd], [], [], BATCH_S)[0]:
            lc.handle()
        if batch and time.monotonic() >= flush_at:
            counters[0] += len(batch)
            out.put(batch)
            batch = []
        if time.monotonic() >= flush_at:
            flush_at = time.monotonic() + BATCH_S


class Receiver:
    def __init__(self, build: Path, url: str, pattern: str) -> None:
        ctx = mp.get_context("spawn")
        self.queue: "mp.Queue[list[PoseTuple]]" = ctx.Queue()
        self.stop_event = ctx.Event()
        self.ready = ctx.Event()
        # poses received, undecodable, Eye poses refused (v2x_auth)
        self.counters = ctx.Array("q", 3, lock=False)
        self.proc = ctx.Process(
            target=run,
            args=(str(build), url, pattern, self.queue, self.stop_event, self.ready, self.counters),
            name="scm-receiver",
            daemon=True,
        )

    def start(self) -> None:
        """Starts the process and waits until it listens (the server says ready only then). No
        wall-time limit: on a loaded machine its start (Python, the LCM types) takes what it
        takes; whoever waits for the server's readiness bounds it (tools/demo by CPU time)."""
        self.proc.start()
        while not self.ready.wait(0.5):
            if not self.proc.is_alive():
                raise RuntimeError(
                    f"the pose receiver process exited with code {self.proc.exitcode} before "
                    "it listened"
                )

    def stop(self) -> None:
        self.stop_event.set()
        self.proc.join(timeout=5)
        if self.proc.is_alive():
            self.proc.kill()
