"""A program's clock, the Python side of autodrive::clock::Clock
(runtime/jetson/core/include/autodrive/core/clock.hpp): one clock for stamps and for staleness,
chosen in the program's config (--clock wall|sim). Wall mode is this machine's clock (a real
town); sim mode follows the simulator's SIM_CLOCK, so that a HIL run judges ages in sim time and
is right at any real-time factor. SIM_CLOCK is believed only forward, by at most MAX_SIM_STEP_S.
A frozen simulator still fails safe: SIM_CLOCK that has not moved for FROZEN_AFTER_S of
monotonic time makes the clock frozen, and fresh() then says stale for everything."""

from __future__ import annotations

import threading
import time

MODES = ("wall", "sim")
MAX_SIM_STEP_S = 10.0  # the largest forward step of SIM_CLOCK believed [s]
# SIM_CLOCK standing still this long [s, monotonic] is a frozen simulator (it ticks every 10 ms
# of sim time: a run paced at 0.01x real time still moves it every second).
FROZEN_AFTER_S = 5.0


class Clock:
    def __init__(self, mode: str) -> None:
        if mode not in MODES:
            raise ValueError(f"clock must be one of {MODES}, got {mode!r}")
        self.mode = mode
        self._sim_s: float | None = None  # the latest SIM_CLOCK [s of sim time]
        self._moved_mono_s = -float("inf")  # when SIM_CLOCK last moved forward [s, monotonic]
        self.refused = 0  # SIM_CLOCK ticks refused: backwards or too far ahead
        self._lock = threading.Lock()

    def on_sim_clock(self, utime_us: int, mono_s: float | None = None) -> bool:
        """Takes a SIM_CLOCK tick (its utime [us]); mono_s: when it came [s, time.monotonic()]
        (tests pass their own). False, and counted, when refused."""
        t = utime_us * 1e-6
        mono = time.monotonic() if mono_s is None else mono_s
        with self._lock:
            now = self._sim_s
            if t < 0 or (now is not None and (t < now or t - now > MAX_SIM_STEP_S)):
                self.refused += 1
                return False
            if now is None or t > now:  # the same time again is no sign of life
                self._moved_mono_s = mono
            self._sim_s = t
            return True

    def now_s(self) -> float | None:
        """Now [s]: wall time, or the latest SIM_CLOCK; None before the first SIM_CLOCK."""
        return time.time() if self.mode == "wall" else self._sim_s

    def frozen(self, mono_s: float | None = None) -> bool:
        """Sim mode: no SIM_CLOCK yet, or none that moved it for FROZEN_AFTER_S before mono_s."""
        if self.mode == "wall":
            return False
        mono = time.monotonic() if mono_s is None else mono_s
        return self._sim_s is None or mono - self._moved_mono_s > FROZEN_AFTER_S

    def fresh(self, since_s: float | None, limit_s: float, mono_s: float | None = None) -> bool:
        """Whether something of time since_s [s, this clock] is less than limit_s old, on a
        clock that is not frozen; None (never happened) is stale."""
        now = self.now_s()
        if since_s is None or now is None or self.frozen(mono_s):
            return False
        return now - since_s < limit_s
