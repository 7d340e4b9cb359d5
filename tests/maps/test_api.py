"""maps.api: what autodrive.maps answers (spawn, slots, slot goals, obstacles, terrain,
walls, lanes, stop lines) agrees with the generated MJCF, parsed with a real XML parser, and with
the JSON sidecar; slot goals put the car's envelope (autodrive.core.vehicle) inside the slot."""
import json
import math
import pathlib
import xml.etree.ElementTree as ET
from types import SimpleNamespace

import pytest

from pyhelpers import REPO_ROOT, almost_equal

ROOT = REPO_ROOT
MAPS = ROOT / "maps"

from autodrive import maps  # noqa: E402
from autodrive.core import vehicle  # noqa: E402
from autodrive.maps import geometry  # noqa: E402

TOL_M = 1e-9


def floats(text: str) -> list[float]:
    return [float(v) for v in text.split()]


def geoms(name: str) -> dict[str, ET.Element]:
    root = ET.parse(MAPS / f"{name}.xml").getroot()
    return {g.get("name"): g for g in root.iter("geom")} | {
        "site:" + s.get("name"): s for s in root.iter("site")
    }


def box_contains(g: ET.Element, p: tuple[float, float], margin: float = 1e-9) -> bool:
    """Whether p lies within a box geom's footprint (its pos, half sizes and euler yaw)."""
    cx, cy, _ = floats(g.get("pos"))
    hx, hy, _ = floats(g.get("size"))
    yaw = floats(g.get("euler", "0 0 0"))[2]
    dx, dy = p[0] - cx, p[1] - cy
    lx = math.cos(yaw) * dx + math.sin(yaw) * dy
    ly = -math.sin(yaw) * dx + math.cos(yaw) * dy
    return abs(lx) <= hx + margin and abs(ly) <= hy + margin


def same_axis(a: float, b: float) -> bool:
    return abs(math.remainder(a - b, math.pi)) < 1e-9


@pytest.fixture(scope="module")
def shipped() -> SimpleNamespace:
    """What every test reads: the shipped maps (and the car), loaded once."""
    ns = SimpleNamespace()
    ns.v = vehicle.load()
    ns.maps = {n: maps.load(n) for n in maps.names()}
    ns.xml = {n: geoms(n) for n in maps.names()}
    ns.json = {n: json.loads((MAPS / f"{n}.json").read_text()) for n in maps.names()}
    return ns


def test_spawn_is_the_mjcf_site_and_the_sidecar(shipped: SimpleNamespace) -> None:
    for n, m in shipped.maps.items():
        site = shipped.xml[n]["site:spawn"]
        p = m.spawn_pose()
        assert floats(site.get("pos"))[:2] == [p.x_m, p.y_m], n
        assert almost_equal(floats(site.get("euler"))[2], p.yaw_rad, 9)
        js = shipped.json[n]["spawn"]
        assert (js["x_m"], js["y_m"]) == (p.x_m, p.y_m)
    assert shipped.maps["parking_school"].spawn_pose() == maps.Pose(-1.0, 0.6, 0.0)


def test_slots_are_the_painted_rectangles(shipped: SimpleNamespace) -> None:
    m, g = shipped.maps["parking_school"], shipped.xml["parking_school"]
    assert [s.name for s in m.parking_slots] == [f"s{k}" for k in range(6)]
    lines = [e for k, e in g.items() if k.startswith("slot_line_")]
    backs = [e for k, e in g.items() if k.startswith("slot_back")]
    assert len(lines) == 7  # shared side lines drawn once
    for k, s in enumerate(m.parking_slots):
        assert m.slot(k) is s
        assert m.slot(s.name) is s
        c = s.corners_m()  # front-left, rear-left, rear-right, front-right (yaw frame)
        # both side edges are a painted line: its centre at the edge's middle, along yaw,
        # as long as the slot is deep
        for a, b in ((c[0], c[1]), (c[2], c[3])):
            mid = ((a[0] + b[0]) / 2, (a[1] + b[1]) / 2)
            hit = [
                e
                for e in lines
                if math.dist(floats(e.get("pos"))[:2], mid) < 1e-9
                and same_axis(floats(e.get("euler"))[2], s.yaw_rad)
                and abs(floats(e.get("size"))[0] - s.size_m[1] / 2) < 1e-9
            ]
            assert len(hit) == 1, (s.name, mid)
        # the back (front, in the yaw direction) edge lies on a back line
        for p in (c[0], c[3]):
            assert any(box_contains(e, p) for e in backs), (s.name, p)
        # the open side has no line
        mid_open = ((c[1][0] + c[2][0]) / 2, (c[1][1] + c[2][1]) / 2)
        assert not any(box_contains(e, mid_open) for e in lines + backs), s.name
    # the drawn row: lines at x = -1.2 + 0.3 k, y = 1.25 (the layout demo_parking copied)
    xs = sorted(floats(e.get("pos"))[0] for e in lines)
    for k, x in enumerate(xs):
        assert almost_equal(x, -1.2 + 0.3 * k, 9)
    js = shipped.json["parking_school"]["parking_slots"]
    for s, j in zip(m.parking_slots, js):
        assert j["name"] == s.name
        assert j["centre_m"] == list(s.centre_m)
        assert almost_equal(j["yaw_rad"], s.yaw_rad, 9)


def test_slot_goal_centres_the_envelope(shipped: SimpleNamespace) -> None:
    m = shipped.maps["parking_school"]
    ahead = shipped.v.envelope_center_ahead_m
    length, width = shipped.v.envelope_length_m, shipped.v.envelope_width_m
    for s in m.parking_slots:
        for direction in ("forward", "reverse"):
            g = m.slot_goal(s, shipped.v, direction)
            cx, cy = g.x_m + ahead * math.cos(g.yaw_rad), g.y_m + ahead * math.sin(g.yaw_rad)
            assert almost_equal(cx, s.centre_m[0], 9)
            assert almost_equal(cy, s.centre_m[1], 9)
            want = s.yaw_rad if direction == "forward" else s.yaw_rad + math.pi
            assert almost_equal(math.remainder(g.yaw_rad - want, 2 * math.pi), 0, 9)
            car = maps.model.rect_corners((cx, cy), (length, width), g.yaw_rad)
            slot = s.corners_m()
            for p in car:  # inside the slot rectangle
                assert _inside(p, slot), (s.name, direction, p)
    g = m.slot_goal(2, shipped.v)  # the demo's slot: base_link behind the slot centre
    assert almost_equal(g.x_m, -0.45, 9)
    assert almost_equal(g.y_m, 1.25 - ahead, 9)
    assert almost_equal(g.yaw_rad, math.pi / 2, 9)


def _inside(p, poly) -> bool:
    sign = 0.0
    for i in range(len(poly)):
        (x0, y0), (x1, y1) = poly[i], poly[(i + 1) % len(poly)]
        cross = (x1 - x0) * (p[1] - y0) - (y1 - y0) * (p[0] - x0)
        if abs(cross) < 1e-12:
            continue
        if sign and (cross > 0) != (sign > 0):
            return False
        sign = cross
    return True


def test_obstacles_are_the_collidable_props(shipped: SimpleNamespace) -> None:
    for n, m in shipped.maps.items():
        g = shipped.xml[n]
        props = {
            k: e
            for k, e in g.items()
            if e.get("contype") == "1"
            and e.get("type") in ("box", "cylinder")
            and not k.startswith("terrain_")
        }
        rects = m.obstacles()
        assert len(rects) == len(props), n
        for e in props.values():
            x, y, z = floats(e.get("pos"))
            size = floats(e.get("size"))
            if e.get("type") == "box":
                hx, hy, hz = size
                yaw = floats(e.get("euler"))[2]
                assert almost_equal(z, hz, 12)  # stands on the floor
            else:
                hx = hy = size[0]
                yaw = 0.0
            want = maps.Rect(x, y, hx, hy, yaw)
            assert any(
                all(abs(a - b) < TOL_M for a, b in zip(vars(r).values(), vars(want).values()))
                for r in rects
            ), (n, e.get("name"), want)


def test_terrain_and_walls_match_the_mjcf(shipped: SimpleNamespace) -> None:
    for n, m in shipped.maps.items():
        g = shipped.xml[n]
        assert floats(g["floor"].get("friction"))[0] == m.kit.surfaces[m.floor_surface].friction
        for p in m.terrain_patches:
            e = g[p.name]
            assert floats(e.get("friction"))[0] == m.kit.surfaces[p.surface].friction
            assert floats(e.get("pos"))[:2] == list(p.centre_m)
            assert floats(e.get("size"))[:2] == [p.size_m[0] / 2, p.size_m[1] / 2]
            j = next(t for t in shipped.json[n]["terrain_patches"] if t["name"] == p.name)
            assert j["friction"] == m.kit.surfaces[p.surface].friction
        for w in m.walls:
            e = g[w.name]
            assert e.get("type") == "plane"
            assert floats(e.get("pos"))[:2] == list(w.face_centre_m)
            assert floats(e.get("zaxis"))[:2] == list(w.normal)
    assert len(shipped.maps["parking_school"].walls) == 4


def test_tile_lanes_run_on_their_tiles(shipped: SimpleNamespace) -> None:
    m = shipped.maps["driving_school"]
    tiles = {t["name"]: t for t in shipped.json["driving_school"]["tiles"]}
    assert len(m.lanes()) == 80
    for lane in m.lanes():
        pts = m.centre_line(lane, 0.05)
        t = tiles[lane.road.name]  # a tile lane's road is its tile
        half = t["size_m"] / 2
        for (x, y, h), (x2, y2, _) in zip(pts, pts[1:]):
            assert abs(x - t["centre_m"][0]) <= half + 1e-9, lane.name
            assert abs(y - t["centre_m"][1]) <= half + 1e-9, lane.name
            assert math.dist((x, y), (x2, y2)) <= 0.05 + 1e-9
            # headings point to the next point
            assert abs(math.remainder(math.atan2(y2 - y, x2 - x) - h, 2 * math.pi)) < 0.1
        j = next(l for l in shipped.json["driving_school"]["lanes"] if l["name"] == lane.name)
        assert len(j["centre_line"]) == len(pts)
        assert almost_equal(j["centre_line"][-1]["x_m"], pts[-1][0], 8)
        assert j["half_width_m"] == m.kit.tiles.lane_width_m / 2
    # right-hand traffic: the west arm's eastbound lane runs +x on the road's south side
    east = m.centre_line("cw_w_e")
    assert almost_equal(east[0][1], -m.kit.tiles.lane_width_m / 2)
    assert east[0][0] < east[-1][0]
    assert almost_equal(abs(m.centre_line("cw_e_w")[0][2]), math.pi)
    # the loop route is closed
    ccw = m.route("loop_ccw").polyline_m
    assert math.dist(ccw[0], ccw[-1]) < 1e-9
    # the spawn stands in the west dead end's eastbound lane, facing along it
    sp = m.spawn_pose()
    d, heading = geometry.nearest_on_polyline((sp.x_m, sp.y_m), m.centre_line("w_end_end_e"))
    assert d < 1e-9
    assert almost_equal(heading, sp.yaw_rad)


def test_free_form_road_lanes(shipped: SimpleNamespace) -> None:
    m = maps.load(ROOT / "tests" / "maps" / "fixtures" / "good_tiny.yaml")
    east = m.centre_line("x_east")
    assert almost_equal(east[0][1], -0.12)
    assert east[0][0] < east[-1][0]
    assert almost_equal(m.lane("x_east").kerb_right_m, 0.25 - 0.12)
    assert almost_equal(m.lane("x_west").kerb_right_m, 0.25 - 0.12)
    assert almost_equal(m.centre_line("x_west")[0][2], -math.pi / 2)


def test_stop_lines_cross_their_lanes(shipped: SimpleNamespace) -> None:
    m = shipped.maps["driving_school"]
    stops = [s for s in m.all_stop_lines() if s.name.startswith("x_stop_")]
    assert len(stops) == 4
    js = {s["name"]: s for s in shipped.json["driving_school"]["stop_lines"]}
    for s in stops:
        d, heading = geometry.nearest_on_polyline(s.centre_m, m.centre_line(s.lane, 0.01))
        assert d < 1e-9
        assert same_axis(js[s.name]["yaw_rad"], heading + math.pi / 2)
        assert js[s.name]["lane"] == s.lane
        # before the intersection (the origin): the lane heads towards it
        to_origin = math.atan2(-s.centre_m[1], -s.centre_m[0])
        assert abs(math.remainder(to_origin - heading, 2 * math.pi)) < math.pi / 2
    assert m.traffic_lights == []
    assert shipped.json["driving_school"]["traffic_lights"] == []
