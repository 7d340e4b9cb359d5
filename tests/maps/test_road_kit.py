"""maps.road_kit: the road kit's tiles and the maps built from them. Every tile type, lane count
and rotation opens the same lanes at the middle of each arm (so any two facing arms connect);
on every shipped map the lane centre lines of neighbouring tiles meet within 1 mm with the same
heading; routes are smooth polylines the car can follow; Intersection School's 12 routes and its
lights' programs (never two crossing lights non-red, >= 1 s all red); Tiny Town has every kit
element; the MJCF carries the contract's names, materials and custom numerics (one fact with
the sidecar); the light level; tools/map show writes a PNG of every map, --help everywhere."""
import json
import math
import pathlib
import re
import subprocess
import tempfile
import xml.etree.ElementTree as ET
from types import SimpleNamespace

import pytest

from pyhelpers import REPO_ROOT

ROOT = REPO_ROOT
MAPS = ROOT / "maps"
TOOL = ROOT / "tools" / "map"

from autodrive import maps  # noqa: E402
from autodrive.core import vehicle  # noqa: E402
from autodrive.maps import tiles  # noqa: E402
from autodrive.maps.model import TileSpec  # noqa: E402

JOIN_M = 0.001
TYPES = (
    "straight",
    "curve",
    "dead_end",
    "tee",
    "cross",
    "parking_lot",
    "roadside_parking",
    "patch",
)


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([str(TOOL), *args], capture_output=True, text=True, timeout=120)


def state(p: maps.model.Program, t: float) -> str:
    u = (t - p.offset_s) % p.cycle_s
    return "green" if u < p.green_s else "yellow" if u < p.green_s + p.yellow_s else "red"


def numeric(root: ET.Element, name: str) -> list[float]:
    """A custom numeric with its .partK continuations (MuJoCo's 500-value limit)."""
    nums = {n.get("name"): n.get("data") for n in root.iter("numeric")}
    out = [float(v) for v in nums[name].split()]
    k = 1
    while f"{name}.part{k}" in nums:
        out += [float(v) for v in nums[f"{name}.part{k}"].split()]
        k += 1
    return out


@pytest.fixture(scope="module")
def shipped() -> SimpleNamespace:
    """What every test reads: the shipped maps (and the car), loaded once."""
    ns = SimpleNamespace()
    ns.maps = {n: maps.load(n) for n in maps.names()}
    ns.kit = maps.load_kit()
    return ns


def test_every_tile_opens_the_same_lanes_on_each_arm(shipped: SimpleNamespace) -> None:
    tk = shipped.kit.tiles
    for tile_type in TYPES:
        for lanes in tiles.LANE_COUNTS:
            for rot in (0.0, 90.0, 180.0, 270.0):
                spec = TileSpec("t", tile_type, lanes, (0.6, -1.2), rot)  # type: ignore[arg-type]
                c = tiles.expand(tk, spec)
                h = c.size_m / 2
                q = round(rot / 90)
                arms = {tiles.SIDES[(tiles.SIDES.index(a) + q) % 4] for a in tiles.ARMS[tile_type]}
                want_in, want_out = set(), set()
                for side in arms:
                    i = tiles.SIDES.index(side)
                    u = (round(math.cos(i * math.pi / 2)), round(math.sin(i * math.pi / 2)))
                    v = (-u[1], u[0])
                    for d in tiles.lane_offsets_m(tk, lanes):
                        p_in = (0.6 + h * u[0] + d * v[0], -1.2 + h * u[1] + d * v[1])
                        p_out = (0.6 + h * u[0] - d * v[0], -1.2 + h * u[1] - d * v[1])
                        want_in.add((round(p_in[0], 6), round(p_in[1], 6), side))
                        want_out.add((round(p_out[0], 6), round(p_out[1], 6), side))
                got_in = {
                    (round(p[0], 6), round(p[1], 6)) for _, e, p, _ in c.ports if e == "start"
                }
                got_out = {(round(p[0], 6), round(p[1], 6)) for _, e, p, _ in c.ports if e == "end"}
                key = (tile_type, lanes, rot)
                assert got_in == {w[:2] for w in want_in}, key
                assert got_out == {w[:2] for w in want_out}, key
                for lane in c.lanes:  # each lane's pieces join, and it is one direction
                    pts = maps.geometry.centre_line(lane, 0.01)
                    for a, b in zip(pts, pts[1:]):
                        assert math.dist(a[:2], b[:2]) <= 0.01 + 1e-9, key
                    # turns are no tighter than the car can follow with margin
                    for p in lane.road.pieces:
                        if p.arc is not None:
                            assert p.arc.radius_m >= 0.45, (key, lane.name)


def test_lane_centre_lines_connect_where_tiles_meet(shipped: SimpleNamespace) -> None:
    for n, m in shipped.maps.items():
        js = json.loads((MAPS / f"{n}.json").read_text())
        firsts = [(l["centre_line"][0], l["name"]) for l in js["lanes"]]
        lasts = [(l["centre_line"][-1], l["name"]) for l in js["lanes"]]
        joins = 0
        for t in m.tile_contents():
            for lane, end, p, yaw in t.ports:
                others = firsts if end == "end" else lasts
                match = [
                    name
                    for q, name in others
                    if name != lane
                    and math.dist(p, (q["x_m"], q["y_m"])) <= JOIN_M
                    and abs(math.remainder(q["heading_rad"] - yaw, 2 * math.pi)) < 1e-3
                ]
                assert match, (n, t.spec.name, lane, end, p)
                joins += 1
        if m.tiles:
            assert joins > 20, n


def test_routes_are_smooth_and_followable(shipped: SimpleNamespace) -> None:
    car = vehicle.load()
    min_radius_m = car.wheelbase_m / math.tan(car.steer_limit_rad)
    for n, m in shipped.maps.items():
        js = {r["name"]: r for r in json.loads((MAPS / f"{n}.json").read_text())["routes"]}
        for r in m.named_routes():
            pts = r.polyline_m
            assert [list(p) for p in pts] == js[r.name]["polyline_m"]
            for a, b in zip(pts, pts[1:]):
                assert math.dist(a, b) <= 0.05 + 1e-9, (n, r.name)
                assert math.dist(a, b) > 0.0, (n, r.name)
            for a, b, c in zip(pts, pts[1:], pts[2:]):
                h1 = math.atan2(b[1] - a[1], b[0] - a[0])
                h2 = math.atan2(c[1] - b[1], c[0] - b[0])
                turn = abs(math.remainder(h2 - h1, 2 * math.pi))
                ds = (math.dist(a, b) + math.dist(b, c)) / 2
                # no kink: the heading turns at most as on a 0.45 m radius
                assert turn <= ds / 0.45 + 1e-6, (n, r.name, b)
                assert 0.45 > 1.5 * min_radius_m  # well above the car's limit
            if r.loop:
                assert math.dist(pts[0], pts[-1]) < 1e-9


def test_intersection_school(shipped: SimpleNamespace) -> None:
    m = shipped.maps["intersection_school"]
    sides = ("north", "east", "south", "west")
    want = {f"{a}_to_{b}" for a in sides for b in sides if a != b}
    assert {r.name for r in m.named_routes()} == want
    outward = {"north": (0, 1), "east": (1, 0), "south": (0, -1), "west": (-1, 0)}
    for r in m.named_routes():
        a, b = r.name.split("_to_")
        p0, p1 = r.polyline_m[0], r.polyline_m[-1]
        assert p0[0] * outward[a][0] + p0[1] * outward[a][1] > 2.5, r.name
        assert p1[0] * outward[b][0] + p1[1] * outward[b][1] > 2.5, r.name
    lights = m.lights()
    assert len(lights) == 4
    assert {l.stop_line for l in lights} == {f"x_stop_{s}" for s in "nesw"}
    for light in lights:  # faces its approach: towards the cars coming to the stop line
        stop = m.stop_line(light.stop_line)
        _, heading = maps.geometry.nearest_on_polyline(stop.centre_m, m.centre_line(stop.lane))
        to_car = heading + math.pi
        assert abs(math.remainder(light.yaw_rad - to_car, 2 * math.pi)) < 1e-9
        # on the kerb to the right of the approaching cars
        dx, dy = light.position_m[0] - stop.centre_m[0], light.position_m[1] - stop.centre_m[1]
        assert math.cos(heading) * dy - math.sin(heading) * dx < -0.1
    conflicts = m.light_conflicts()
    assert len(conflicts) == 4
    by_id = {l.id: l.program for l in lights}
    for a, b in conflicts:
        red_both_s, t = 0.0, 0.0
        longest_all_red = 0.0
        while t < 40.0:
            sa, sb = state(by_id[a], t), state(by_id[b], t)
            assert not (sa != "red" and sb != "red"), (a, b, t)
            red_both_s = red_both_s + 0.05 if sa == sb == "red" else 0.0
            longest_all_red = max(longest_all_red, red_both_s)
            t += 0.05
        assert longest_all_red >= 1.0 - 1e-6


def test_tiny_town_has_every_kit_element(shipped: SimpleNamespace) -> None:
    m = shipped.maps["tiny_town"]
    assert {t.type for t in m.tiles} == set(TYPES)
    assert {t.lanes for t in m.tiles if t.type != "patch"} == {1, 2, 4, 6}
    assert sum(t.type in ("tee", "cross") for t in m.tiles) >= 2
    terrains = {p.surface for p in m.terrain_patches} | {m.floor_surface}
    assert terrains == set(m.kit.surfaces)
    assert len(m.lights()) >= 4
    assert {s.kind for s in m.signs} == set(m.kit.sign.kinds)
    for cat in ("regulatory", "cautionary", "informatory"):
        assert cat in {m.kit.sign.kinds[s.kind].category for s in m.signs}
    assert m.boxes and m.cones and m.late_obstacles and m.parked
    assert any(r.loop for r in m.named_routes())
    assert m.spawns


def test_mjcf_carries_the_contract(shipped: SimpleNamespace) -> None:
    for n, m in shipped.maps.items():
        root = ET.parse(MAPS / f"{n}.xml").getroot()
        g = {e.get("name"): e for e in root.iter("geom")}
        mats = {e.get("name"): e for e in root.iter("material")}
        js = json.loads((MAPS / f"{n}.json").read_text())
        for name, e in g.items():  # visual-only parts neither collide nor weigh
            if name.startswith("tile_") or re.search(r"_(housing|lamp_\w+|face|back)$", name):
                assert (e.get("contype"), e.get("conaffinity")) == ("0", "0"), name
            if re.search(r"_(pole|post)$", name):
                assert e.get("contype") == "1", name
        for light in js["traffic_lights"]:
            tl = light["name"]
            assert tl == f"tl{light['id']}"
            for part in ("pole", "housing", "lamp_red", "lamp_yellow", "lamp_green"):
                assert f"{tl}_{part}" in g
            for c in ("red", "yellow", "green"):
                assert g[f"{tl}_lamp_{c}"].get("material") == f"{tl}_lamp_{c}_mat"
                assert f"{tl}_lamp_{c}_mat" in mats
            p = light["program"]
            want = [p["cycle_s"], p["offset_s"], p["green_s"], p["yellow_s"]]
            assert numeric(root, f"{tl}_program") == want
        if js["light_conflicts"]:
            flat = [float(v) for pair in js["light_conflicts"] for v in pair]
            assert numeric(root, "tl_conflicts") == flat
        for sign in js["signs"]:
            assert f"{sign['name']}_post" in g
            assert f"{sign['name']}_face" in g
        for r in js["routes"]:
            data = numeric(root, f"route_{r['name']}")
            assert data[0] == (1.0 if r["loop"] else 0.0)
            assert data[1] == r["half_width_m"]
            pts = [v for p in r["polyline_m"] for v in p]
            assert len(data) - 2 == len(pts), r["name"]
            assert max(abs(a - b) for a, b in zip(data[2:], pts)) < 1e-6
        for lane in js["lanes"]:
            data = numeric(root, f"lane_{lane['name']}")
            assert data[0] == lane["half_width_m"]
            assert len(data) - 1 == 2 * len(lane["centre_line"])
        sites = {s.get("name") for s in root.iter("site")}
        for s in js["spawns"]:
            assert f"spawn_{s['name']}" in sites
        for t in root.iter("texture"):
            if t.get("file"):
                assert not t.get("file").startswith("/")
                assert (MAPS / t.get("file")).is_file(), t.get("file")
        for nm in root.iter("numeric"):
            assert len(nm.get("data").split()) <= 500, nm.get("name")


def test_light_level_dims_the_map(shipped: SimpleNamespace) -> None:
    from autodrive.maps import mjcf

    with tempfile.TemporaryDirectory() as tmp:
        y = pathlib.Path(tmp) / "intersection_school.yaml"
        text = (MAPS / "intersection_school.yaml").read_text()
        y.write_text(text.replace("light_level: 1.0", "light_level: 0.25"))
        root = ET.fromstring(mjcf.generate(maps.load(y)))
    hl = root.find("visual/headlight")
    assert hl.get("diffuse") == "0.1 0.1 0.1"
    sun = next(l for l in root.iter("light") if l.get("name") == "sun")
    assert sun.get("diffuse") == "0.2 0.2 0.2"
    day = ET.parse(MAPS / "intersection_school.xml").getroot()
    assert day.find("visual") is None  # day: MuJoCo's own headlight


def test_map_show_writes_a_png_of_every_map(shipped: SimpleNamespace) -> None:
    from PIL import Image

    with tempfile.TemporaryDirectory() as tmp:
        for n in maps.names():
            out = pathlib.Path(tmp) / f"{n}.png"
            r = run("show", n, "--out", str(out))
            assert r.returncode == 0, r.stderr
            assert out.stat().st_size > 20_000, n
            with Image.open(out) as img:
                assert img.size[0] > 500
                # not blank: many colours (tiles, lanes, markers)
                assert len(img.convert("RGB").getcolors(1 << 20) or []) > 50


def test_help_on_every_subcommand(shipped: SimpleNamespace) -> None:
    for args in (("--help",), ("show", "--help"), ("check", "--help")):
        r = run(*args)
        assert r.returncode == 0, (args, r.stderr)
        assert "usage" in r.stdout
    r = run("show", "moon_base")
    assert r.returncode == 2
    assert "moon_base.yaml: no such map description" in r.stderr
