"""The simulator's TRAFFIC_LIGHT_STATE as received here, on a background thread: what the SCM
tests and tools/bench scm watch to see a click reach the lights."""

from __future__ import annotations

import threading
import time
from typing import Any

from autodrive.core.channels import channel


class LightWatch:
    """TRAFFIC_LIGHT_STATE messages as (wall time received [s], light id, state), and each
    message's own stamp (the simulator's clock [s]) beside it in sim_s."""

    def __init__(self, lc: Any, types: Any, poll_ms: int = 20) -> None:
        self.states: list[tuple[float, int, int]] = []
        self.sim_s: list[float] = []
        self.T = types
        self.lc = lc
        self.poll_ms = poll_ms
        lc.subscribe(channel("TRAFFIC_LIGHT_STATE"), self._on)
        self.stop_flag = threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _on(self, _c: str, data: bytes) -> None:
        m = self.T.traffic_light_state_t.decode(data)
        self.sim_s.append(m.utime * 1e-6)  # first: states[k] always has its stamp
        self.states.append((time.time(), int(m.light_id), int(m.state)))

    def _run(self) -> None:
        while not self.stop_flag.is_set():
            self.lc.handle_timeout(self.poll_ms)

    def latest(self, light_id: int) -> int | None:
        """The light's last state received, None before any."""
        for _, i, s in reversed(self.states):
            if i == light_id:
                return s
        return None

    def first_after(self, light_id: int, state: int, t: float) -> float | None:
        """Wall time [s] the light was first seen in the state at or after t [s], else None."""
        for tr, i, s in list(self.states):
            if tr >= t and i == light_id and s == state:
                return tr
        return None

    def first_sim_s_after(self, light_id: int, state: int, t: float) -> float | None:
        """The simulator's stamp [s] of the first message in the state received at or after
        wall time t [s], else None: durations of the lights on their own clock."""
        for k, (tr, i, s) in enumerate(list(self.states)):
            if tr >= t and i == light_id and s == state:
                return self.sim_s[k]
        return None

    def stop(self) -> None:
        self.stop_flag.set()
        self.thread.join()
