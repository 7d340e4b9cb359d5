"""maps.map_check: `tools/map check` on tests/maps/fixtures/town/: good_town.yaml passes and each
bad_*.yaml (good_town with one mistake, one per class of error) exits 1 with a message naming
the file, the element (dotted key) and what is wrong; the shipped maps pass."""
import pathlib
import subprocess
import sys
import unittest

ROOT = pathlib.Path(sys.argv[1])
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


class MapCheck(unittest.TestCase):
    def test_every_bad_fixture_is_covered(self) -> None:
        self.assertEqual(sorted(p.name for p in FIX.glob("bad_*.yaml")), sorted(EXPECTED))

    def test_good_fixture_and_shipped_maps_pass(self) -> None:
        r = check(str(FIX / "good_town.yaml"), "parking_school", "driving_school",
                  "intersection_school", "tiny_town")  # fmt: skip
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(r.stdout.count(": ok ("), 5)

    def test_each_bad_fixture_names_file_element_and_problem(self) -> None:
        r = check(*(str(FIX / name) for name in EXPECTED))  # one run checks them all
        self.assertEqual(r.returncode, 1, r.stdout)
        self.assertEqual(r.stdout, "")
        lines = r.stderr.splitlines()
        self.assertEqual(len(lines), len(EXPECTED), r.stderr)
        for name, (key, words) in EXPECTED.items():
            with self.subTest(name):
                line = next(l for l in lines if l.startswith(f"map check: {FIX / name}: "))
                self.assertIn(f"map check: {FIX / name}: {key}: ", line)
                self.assertIn(words, line)

    def test_one_bad_file_among_good_ones_fails_the_run(self) -> None:
        r = check(str(FIX / "good_town.yaml"), str(FIX / "bad_tile_gap.yaml"))
        self.assertEqual(r.returncode, 1)
        self.assertIn("good_town.yaml: ok", r.stdout)
        self.assertIn("bad_tile_gap.yaml: tiles[0]", r.stderr)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
