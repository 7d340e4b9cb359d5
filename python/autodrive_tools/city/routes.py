"""Looping routes through the lights, found in the map's lane graph (a lane follows another
when it starts within 2 mm of where that one ends): the shortest loop that drives the given
lanes in order. Tiny Town's named loops (loop_ccw, loop_cw) go round the town and meet no
light, so the smart-city cars also drive loops through its crossroads."""

from __future__ import annotations

import json
import math
from collections import deque
from pathlib import Path

CONNECT_TOL_M = 0.002

# The smart-city mission's three cars on Tiny Town: (route for the driver, start lane).
# Northbound through light 3 and the stop sign, then east; southbound through light 1, then
# west (curve sign); and the map's own loop_ccw (speed-limit and curve signs). None crosses
# another's path except at the lights, whose programs never give two conflicting approaches
# right of way.
TINY_TOWN_VIA = (("x_s_n", "tn_s_e"), ("x_n_s", "ts_n_w"))


def lane_graph(map_json: Path) -> dict[str, list[str]]:
    d = json.loads(map_json.read_text())
    ends = {
        lane["name"]: (
            (lane["centre_line"][0]["x_m"], lane["centre_line"][0]["y_m"]),
            (lane["centre_line"][-1]["x_m"], lane["centre_line"][-1]["y_m"]),
        )
        for lane in d["lanes"]
    }
    return {
        a: sorted(b for b in ends if b != a and math.dist(ends[a][1], ends[b][0]) < CONNECT_TOL_M)
        for a in ends
    }


def _path(graph: dict[str, list[str]], src: str, dst: str) -> list[str]:
    """Shortest lane chain from a successor of src to dst (both excluded from the start)."""
    prev: dict[str, str] = {}
    q = deque([src])
    while q:
        a = q.popleft()
        for b in graph[a]:
            if b in prev or b == src:
                continue
            prev[b] = a
            if b == dst:
                chain = [b]
                while chain[-1] != src:
                    chain.append(prev[chain[-1]])
                return list(reversed(chain))[1:]
            q.append(b)
    raise ValueError(f"no lane chain from {src} to {dst}")


def loop_through(map_json: Path, via: tuple[str, ...]) -> list[str]:
    """The lanes of the shortest loop that drives `via` in order (first lane first)."""
    graph = lane_graph(map_json)
    for v in via:
        if v not in graph:
            raise ValueError(f"{map_json}: no lane {v!r}")
    lanes = [via[0]]
    for nxt in (*via[1:], via[0]):
        lanes += _path(graph, lanes[-1], nxt)
    lanes.pop()  # back at the first lane
    if len(set(lanes)) != len(lanes):
        raise ValueError(f"the loop through {via} drives a lane twice: {lanes}")
    return lanes


def route_arg(lanes: list[str]) -> str:
    """The city driver's --route for a loop of lanes."""
    return "lanes:" + ",".join(lanes)
