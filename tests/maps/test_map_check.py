"""maps.map_check: `tools/map check` on tests/maps/fixtures/town/: good_town.yaml passes and each
bad_*.yaml (good_town with one mistake, one per class of error) exits 1 with a message naming
the file, the element (dotted key) and what is wrong; the shipped maps pass."""
import pathlib
import subprocess

from pyhelpers import REPO_ROOT

ROOT = REPO_ROOT
FIX = ROOT / "tests" / "maps" / "fixtures" / "town"
TOOL = ROOT / "tools" / "map"

# fixture: (element, words of the problem)
EXPECTED = {
    "bad_tile_gap.yaml": ("tiles[0]", "tile 'x' does not connect: its lane 'x_e_n' enters"),
    "bad_tile_rotation.yaml": ("tiles[2].rotation_deg", "must be a multiple of 90, got 45"),
    "bad_tile_lanes.yaml": ("tiles[0].lanes", "must be one of [1, 2, 4, 6], got 3"),
    "bad_tile_overlap.yaml": ("tiles[4]", "tile 'p' overlaps tile 'x'"),
    "bad_route_gap.yaml": ("routes[0].lanes[1]", "does not start where lane 'w_end_e' ends"),
    "bad_route_lane.yaml": ("routes[0].lanes[0]", "no lane 'w_start'"),
    "bad_light_stop_line.yaml": ("traffic_lights[0].stop_line", "no stop line 'x_stop_q'"),
    "bad_light_all_red.yaml": (
        "traffic_lights[1].program",
        "all-red interval between them is 0.5 s",
    ),
    "bad_light_program.yaml": ("traffic_lights[0].program", "green_s + yellow_s must be < cycle_s"),
    "bad_duplicate_light_id.yaml": ("traffic_lights[1].id", "'tl1' is already used"),
    "bad_sign_off_map.yaml": ("signs[1].position_m", "(3.5, -0.6) is off the floor"),
    "bad_sign_kind.yaml": ("signs[0].kind", "unknown sign kind 'yield'"),
    "bad_speed_limit.yaml": ("signs[1].speed_limit_m_s", "a speed_limit sign needs one"),
    "bad_spawn_route.yaml": ("spawns[0].route", "no route 'east_to_west'"),
    "bad_parked_slot.yaml": ("parked[0].slot", "no parking slot 's9'"),
    "bad_late_obstacle.yaml": ("late_obstacles[0]", "exactly one of appear_s and trigger_radius_m"),
    "bad_light_level.yaml": ("options.light_level", "must be in 0..1, got 1.5"),
}


def check(*files: str) -> subprocess.CompletedProcess:
    return subprocess.run([str(TOOL), "check", *files], capture_output=True, text=True, timeout=120)


def test_every_bad_fixture_is_covered() -> None:
    assert sorted(p.name for p in FIX.glob("bad_*.yaml")) == sorted(EXPECTED)


def test_good_fixture_and_shipped_maps_pass() -> None:
    r = check(str(FIX / "good_town.yaml"), "parking_school", "driving_school",
              "intersection_school", "tiny_town")  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert r.stdout.count(": ok (") == 5


def test_each_bad_fixture_names_file_element_and_problem() -> None:
    r = check(*(str(FIX / name) for name in EXPECTED))  # one run checks them all
    assert r.returncode == 1, r.stdout
    assert r.stdout == ""
    lines = r.stderr.splitlines()
    assert len(lines) == len(EXPECTED), r.stderr
    for name, (key, words) in EXPECTED.items():
        line = next(l for l in lines if l.startswith(f"map check: {FIX / name}: "))
        assert f"map check: {FIX / name}: {key}: " in line
        assert words in line


def test_one_bad_file_among_good_ones_fails_the_run() -> None:
    r = check(str(FIX / "good_town.yaml"), str(FIX / "bad_tile_gap.yaml"))
    assert r.returncode == 1
    assert "good_town.yaml: ok" in r.stdout
    assert "bad_tile_gap.yaml: tiles[0]" in r.stderr
