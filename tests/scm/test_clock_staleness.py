"""The SCM's freshness on its clock, unit-tested on a sim clock the test advances (event order,
no wall time): a car's pose is fresh for STALE_S of sim time, an Eye pose is preferred for
EYE_PREFERRED_S of sim time, and a frozen SIM_CLOCK (still for FROZEN_AFTER_S of monotonic time)
makes every pose stale. autodrive.core.clock.Clock itself: forward-only ticks, refused ones
counted. The Scm is built on a real SQLite database and never started (no threads, no LCM
traffic). Args: ROOT BUILD."""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from autodrive import maps
from autodrive.core import clock
from autodrive.scm.core.db import migrate, open_engine
from autodrive.scm.service import EYE_PREFERRED_S, STALE_S, Scm


def test_clock_forward_only_and_frozen() -> None:
    c = clock.Clock("sim")
    assert c.now_s() is None and c.frozen(0.0) and not c.fresh(0.0, 1.0, 0.0)
    assert c.on_sim_clock(5_000_000, mono_s=100.0)
    assert not c.on_sim_clock(4_000_000, mono_s=100.0)  # backwards: refused
    assert not c.on_sim_clock(5_000_000 + 11_000_000, mono_s=100.0)  # too far ahead: refused
    assert c.refused == 2 and c.now_s() == 5.0
    assert c.fresh(4.6, 0.5, mono_s=100.0) and not c.fresh(4.5, 0.5, mono_s=100.0)
    assert c.on_sim_clock(5_000_000, mono_s=100.0 + clock.FROZEN_AFTER_S)  # same time: believed
    assert c.frozen(mono_s=100.0 + clock.FROZEN_AFTER_S + 0.001)  # ... but no sign of life
    assert not c.fresh(5.0, 0.5, mono_s=100.0 + clock.FROZEN_AFTER_S + 0.001)
    assert c.on_sim_clock(5_010_000, mono_s=200.0) and not c.frozen(mono_s=200.0)
    w = clock.Clock("wall")
    assert not w.frozen(1e9) and w.fresh(time.time(), 60.0)


def test_scm_freshness_on_the_sim_clock(build_dir: Path) -> None:
    with tempfile.TemporaryDirectory(prefix="scm-clock-unit-") as tmp:
        engine = open_engine(f"sqlite:///{tmp}/scm.sqlite")
        migrate(engine)
        scm = Scm(maps.load("tiny_town"), engine, build_dir, "memq://", ["NIGEL1"], clock="sim")
        mono = time.monotonic()  # the frozen() backstop's time: the ticks below are all "now"
        advised: list[str] = []
        scm._publish = lambda chan, _data: advised.append(chan)  # type: ignore[method-assign]
        scm.time.on_sim_clock(10_000_000, mono)
        scm.pose("NIGEL1", 10_000_000, 1.0, 1.0, 0.0, 0.0, "eye")
        car = scm.cars["NIGEL1"]
        assert car.seen_c == 10.0 and car.eye_seen_c == 10.0
        scm._advise(time.time(), scm.city_now())
        assert len(advised) == 1, "a fresh pose gets an advisory"
        # an EKF pose within EYE_PREFERRED_S of sim time after the Eye's is not kept
        scm.time.on_sim_clock(int((10.0 + EYE_PREFERRED_S / 2) * 1e6), mono)
        scm.pose("NIGEL1", 10_200_000, 2.0, 2.0, 0.0, 0.0, "ekf")
        assert car.source == "eye" and car.x_m == 1.0
        # STALE_S of sim time without a pose: no advisory, whatever the wall time did
        scm.time.on_sim_clock(int((10.0 + STALE_S + 0.01) * 1e6), mono)
        scm._advise(time.time(), scm.city_now())
        assert len(advised) == 1 and car.status == "stale"
        # the EKF pose is kept once the Eye's is older than EYE_PREFERRED_S of sim time
        scm.pose("NIGEL1", 10_600_000, 2.0, 2.0, 0.0, 0.0, "ekf")
        assert car.source == "ekf"
        scm._advise(time.time(), scm.city_now())
        assert len(advised) == 2
        # a frozen simulator: SIM_CLOCK still for FROZEN_AFTER_S of monotonic time -> stale
        assert not scm.time.fresh(car.seen_c, STALE_S, mono + clock.FROZEN_AFTER_S + 1.0)
        engine.dispose()
