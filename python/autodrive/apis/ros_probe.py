"""Counts a car's bridged topics on both sides over one window of sim time, for the ROS test
and `tools/bench apis`: every ROS message's header stamp (the /clock message's clock) and every
LCM message's utime, so a rate is judged on message stamps, never on a wall deadline. The caller
spins the LCM side (lc.handle); rospy calls back on its own threads."""

from __future__ import annotations

import importlib
import struct
import threading
from typing import Any

from autodrive.core import lcmtypes
from autodrive.ros import topics

CLOCK = topics.CLOCK_ID


def ros_class(ros_type: str) -> Any:
    """The message class of "package/Name" (Debian's python3-<package> modules)."""
    package, name = ros_type.split("/")
    return getattr(importlib.import_module(package + ".msg"), name)


class RateProbe:
    """Stamps [us] per channel id, on ROS and on LCM; .clock_us is the newest SIM_CLOCK."""

    def __init__(self, rospy: Any, types: Any, lc: Any, car: str, ids: tuple[str, ...]) -> None:
        self.lock = threading.Lock()
        self.table = {t.channel_id: t for t in topics.state_topics([car]) if t.channel_id in ids}
        self.ros: dict[str, list[int]] = {k: [] for k in ids}
        self.lcm: dict[str, list[int]] = {k: [] for k in ids}
        self.types = types
        self.clock_us: int | None = None
        self.first_clock_us: int | None = None
        self.last_ros: dict[str, Any] = {}
        # Raw messages (rospy.AnyMsg): the stamp is read from the bytes, which spares this
        # process deserialising hundreds of messages a second on a loaded machine.
        self.subs = [
            rospy.Subscriber(
                t.topic, rospy.AnyMsg, self._on_ros(k), queue_size=2000, tcp_nodelay=True
            )
            for k, t in self.table.items()
        ]
        self.by_channel = {t.channel: k for k, t in self.table.items()}
        for ch in self.by_channel:
            lc.subscribe(ch, self._on_lcm)

    def _on_ros(self, key: str) -> Any:
        # rosgraph_msgs/Clock is one time (secs, nsecs: uint32 LE); a stamped message starts
        # with its std_msgs/Header: seq (uint32), then the stamp.
        offset = 0 if key == CLOCK else 4

        def callback(msg: Any) -> None:
            secs, nsecs = struct.unpack_from("<II", msg._buff, offset)
            with self.lock:
                self.ros[key].append(secs * 1_000_000 + nsecs // 1000)
                self.last_ros[key] = msg

        return callback

    def _on_lcm(self, channel: str, data: bytes) -> None:
        key = self.by_channel[channel]
        msg = getattr(self.types, self.table[key].lcm_type).decode(data)
        with self.lock:
            self.lcm[key].append(msg.utime)
        if key == CLOCK:
            self.clock_us = msg.utime
            if self.first_clock_us is None:
                self.first_clock_us = msg.utime

    def use_lcm_log(self, path: str) -> None:
        """Takes the LCM side's counts from a log that lcm-logger (C, which keeps up where this
        process may not on a loaded machine) recorded of the same channels."""
        stamps: dict[str, list[int]] = {k: [] for k in self.lcm}
        events = lcmtypes.events(path)
        while True:
            try:
                ev = next(events)
            except (StopIteration, OSError, ValueError):
                break  # the end, or the logger's last event half written
            key = self.by_channel.get(ev.channel)
            if key is not None:
                stamps[key].append(
                    getattr(self.types, self.table[key].lcm_type).decode(ev.data).utime
                )
        with self.lock:
            self.lcm = stamps

    def sim_s(self) -> float | None:
        """Sim time since the first SIM_CLOCK [s], or None before one."""
        if self.clock_us is None or self.first_clock_us is None:
            return None
        return (self.clock_us - self.first_clock_us) * 1e-6

    def last(self, key: str) -> Any:
        """The newest ROS message of a channel id, deserialised."""
        with self.lock:
            raw = self.last_ros[key]
        return ros_class(self.table[key].ros_type)().deserialize(raw._buff)

    def connected_s(self) -> float | None:
        """The sim time [s of sim_s] by which every topic had delivered its first ROS message
        (ROS connects a subscriber some time after it asks), or None before."""
        with self.lock:
            if self.first_clock_us is None or not all(self.ros.values()):
                return None
            return (max(v[0] for v in self.ros.values()) - self.first_clock_us) * 1e-6

    def window(self, earliest_s: float, length_s: float) -> tuple[float, float] | None:
        """A counting window of length_s starting at earliest_s, or later once every topic is
        connected (0.5 s after): None until then."""
        c = self.connected_s()
        return (
            None if c is None else (max(earliest_s, c + 0.5), max(earliest_s, c + 0.5) + length_s)
        )

    def counts(self, lo_s: float, hi_s: float) -> dict[str, tuple[int, int]]:
        """Per channel id, (ROS, LCM) messages stamped in [lo_s, hi_s) of sim_s."""
        assert self.first_clock_us is not None
        lo, hi = self.first_clock_us + int(lo_s * 1e6), self.first_clock_us + int(hi_s * 1e6)
        with self.lock:
            return {
                k: (sum(lo <= t < hi for t in self.ros[k]), sum(lo <= t < hi for t in self.lcm[k]))
                for k in self.table
            }

    def channel_regex(self) -> str:
        """The counted channels, as lcm-logger's --channel regex."""
        return "|".join(sorted(self.by_channel))

    def close(self) -> None:
        for s in self.subs:
            s.unregister()


def topic_of(car: str, channel_id: str) -> str:
    return next(t.topic for t in topics.state_topics([car]) if t.channel_id == channel_id)
