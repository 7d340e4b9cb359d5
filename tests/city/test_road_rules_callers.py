"""The Smart City Manager (autodrive.scm: its road network from the map description) and its
advisory stand-in (autodrive.hil.city.advisory: from the map's sidecar JSON) say the same next
light and sign on every pose (2 cm apart, on and 5 cm beside the centre line) of every Tiny Town
route: both go through the one C library, common/road_rules, which the city driver's tracks
are checked against in city.unit.RoadRules. Bad sidecar input is named."""

from __future__ import annotations

import copy
import json
import math

import pytest

from autodrive import maps
from autodrive.core.road_rules import RoadNet, SidecarError
from autodrive.hil.city.advisory import Advisor
from autodrive.maps.loader import MAPS_DIR
from autodrive.scm.roadnet import for_map

MAP = "tiny_town"


def route_poses(polyline: list[list[float]], step_m: float = 0.02):
    for a, b in zip(polyline, polyline[1:]):
        seg = math.dist(a, b)
        if seg == 0:
            continue
        yaw = math.atan2(b[1] - a[1], b[0] - a[0])
        n = max(1, int(seg / step_m))
        for k in range(n):
            u = k / n
            yield a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1]), yaw


def test_scm_and_standin_agree_on_every_pose() -> None:
    m = maps.load(MAP)
    scm = for_map(m)
    doc = json.loads((MAPS_DIR / f"{MAP}.json").read_text())
    routes = {r["name"]: r["polyline_m"] for r in doc["routes"]}
    assert set(routes) == set(scm.routes)
    lights_seen = set()
    for name, polyline in routes.items():
        for offset_m in (-0.05, 0.0, 0.05):
            standin = Advisor(RoadNet.from_file(MAPS_DIR / f"{MAP}.json"), {"CAR": name})
            place = None
            for x, y, yaw in route_poses(polyline):
                x2, y2 = x - offset_m * math.sin(yaw), y + offset_m * math.cos(yaw)
                place, want = scm.follow(x2, y2, yaw, name, place)
                assert place is not None, f"{name}: the SCM placed no car at ({x2:.3f}, {y2:.3f})"
                got = standin.ahead("CAR", x2, y2, yaw)
                where = f"{name} at ({x2:.3f}, {y2:.3f}) on {place.lane}"
                assert (got.light_id, got.sign_id, got.sign_kind) == (
                    want.light_id, want.sign_id, want.sign_kind), where  # fmt: skip
                assert got.stop_line_distance_m == pytest.approx(
                    want.stop_line_distance_m, abs=1e-6
                )
                assert got.sign_distance_m == pytest.approx(want.sign_distance_m, abs=1e-6)
                assert got.speed_limit_m_s == want.speed_limit_m_s, where
                lights_seen.add(want.light_id)
    assert lights_seen >= {1, 3, 4}, f"the routes pass lights 1, 3 and 4: saw {lights_seen}"


def test_a_route_sees_past_a_fork() -> None:
    """Without its route the walk stops at a fork; with it, the light beyond is found (the
    stand-in once lost the light on the non-loop routes for want of the car's route)."""
    net = RoadNet.from_file(MAPS_DIR / f"{MAP}.json")
    place = net.place(*net.lanes["n2_e_w"].pts[5], route="north_to_lot")
    assert place is not None and place.lane == "n2_e_w"
    assert net.ahead(place).light_id == -1  # n2_e_w forks into tn_e_w and tn_e_s
    assert net.ahead(place, "north_to_lot").light_id == 1


def bad(doc: dict, edit) -> str:
    d = copy.deepcopy(doc)
    edit(d)
    with pytest.raises(SidecarError) as err:
        RoadNet(d, "planted.json")
    return str(err.value)


def test_bad_sidecar_is_named() -> None:
    doc = json.loads((MAPS_DIR / f"{MAP}.json").read_text())
    lane = doc["lanes"][3]["name"]
    msg = bad(doc, lambda d: d["lanes"][3].update(centre_line=d["lanes"][3]["centre_line"][:1]))
    assert "planted.json" in msg and "lane 3" in msg, msg
    msg = bad(doc, lambda d: d["traffic_lights"][0].update(stop_line="nowhere"))
    assert "traffic light 1" in msg and "nowhere" in msg, msg
    msg = bad(doc, lambda d: d["routes"][0]["lanes"].append("no_such_lane"))
    assert "no_such_lane" in msg, msg
    msg = bad(doc, lambda d: d["lanes"][0].pop("half_width_m"))
    assert "half_width_m" in msg, msg
    assert lane in json.dumps(doc)
