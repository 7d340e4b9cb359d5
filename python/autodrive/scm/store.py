"""The SCM's one database writer: a thread that takes poses, vehicle updates, light states and
events from a queue and writes them in one transaction every batch_s. A caller that needs to
know its rows are on disk (REST ingest) passes a threading.Event, set after the commit."""

from __future__ import annotations

import queue
import threading
import time
from dataclasses import dataclass, field
from typing import Any

from sqlalchemy import insert, select, update
from sqlalchemy.orm import Session, sessionmaker

from autodrive.scm.models import Base, Light, Vehicle

POSES = Base.metadata.tables["poses"]
EVENTS = Base.metadata.tables["events"]


@dataclass
class Batch:
    poses: list[dict[str, Any]] = field(default_factory=list)
    vehicles: dict[str, dict[str, Any]] = field(default_factory=dict)
    lights: dict[int, dict[str, Any]] = field(default_factory=dict)
    events: list[dict[str, Any]] = field(default_factory=list)
    acks: list[threading.Event] = field(default_factory=list)

    def empty(self) -> bool:
        return not (self.poses or self.vehicles or self.lights or self.events or self.acks)


MAX_BATCH = 5000  # poses per transaction: commits (and acknowledgements) stay regular


class Writer:
    def __init__(self, sessions: sessionmaker[Session], batch_s: float = 0.05) -> None:
        self.sessions = sessions
        self.batch_s = batch_s
        self.q: queue.Queue[tuple[str, Any]] = queue.Queue()
        self.known: set[str] = set()
        with sessions() as s:
            self.known.update(s.scalars(select(Vehicle.name)))
        self.rows_written = 0
        self.errors = 0
        self.in_flight = 0  # items of the batch being written
        self.last_error = ""
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="scm-writer", daemon=True)

    def start(self) -> None:
        self._thread.start()

    def alive(self) -> bool:
        return self._thread.is_alive()

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(timeout=10)

    @property
    def pending(self) -> int:
        """Items queued or being written, not yet committed."""
        return self.q.qsize() + self.in_flight

    def pose(self, row: dict[str, Any]) -> None:
        self.q.put(("pose", row))

    def vehicle(self, name: str, values: dict[str, Any]) -> None:
        self.q.put(("vehicle", (name, values)))

    def light(self, light_id: int, values: dict[str, Any]) -> None:
        self.q.put(("light", (light_id, values)))

    def event(self, row: dict[str, Any]) -> None:
        self.q.put(("event", row))

    def ack(self, done: threading.Event) -> None:
        """done is set once everything queued before it is committed."""
        self.q.put(("ack", done))

    def _collect(self) -> Batch:
        b = Batch()
        deadline = time.monotonic() + self.batch_s
        while True:
            left = deadline - time.monotonic()
            try:
                kind, item = self.q.get(timeout=max(0.0, left)) if left > 0 else self.q.get_nowait()
            except queue.Empty:
                return b
            if kind == "pose":
                b.poses.append(item)
                if len(b.poses) >= MAX_BATCH:
                    return b
            elif kind == "vehicle":
                b.vehicles.setdefault(item[0], {}).update(item[1])
            elif kind == "light":
                b.lights.setdefault(item[0], {}).update(item[1])
            elif kind == "event":
                b.events.append(item)
            else:
                b.acks.append(item)

    def _run(self) -> None:
        while not (self._stop.is_set() and self.q.empty()):
            b = self._collect()
            if b.empty():
                continue
            self.in_flight = len(b.poses) + len(b.events) + len(b.vehicles) + len(b.lights) + 1
            try:
                self._write(b)
            except Exception as err:  # keep serving; the error is counted and shown in /api/status
                self.errors += 1
                self.last_error = f"{type(err).__name__}: {str(err).splitlines()[0]}"
                continue
            finally:
                self.in_flight = 0
            for done in b.acks:
                done.set()

    def _write(self, b: Batch) -> None:
        with self.sessions() as s, s.begin():
            names = {p["vehicle"] for p in b.poses} | set(b.vehicles)
            new = sorted(names - self.known)
            if new:
                s.execute(
                    insert(Vehicle),
                    [
                        {
                            "name": n,
                            "x_m": 0.0,
                            "y_m": 0.0,
                            "yaw_rad": 0.0,
                            "speed_m_s": 0.0,
                            "source": "",
                            "route": "",
                            "lane": "",
                            "status": "unseen",
                            "updated_us": 0,
                        }
                        for n in new
                    ],
                )
            if b.vehicles:
                s.execute(update(Vehicle), [{"name": n, **v} for n, v in b.vehicles.items()])
            if b.poses:  # Core executemany: no ORM objects for the bulk of the rows
                s.execute(insert(POSES), b.poses)
            if b.lights:
                s.execute(update(Light), [{"id": i, **v} for i, v in b.lights.items()])
            if b.events:
                s.execute(insert(EVENTS), b.events)
        self.known.update(new)
        self.rows_written += len(b.poses) + len(b.events)
