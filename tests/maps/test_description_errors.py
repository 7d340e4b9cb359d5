"""maps.description_errors: each fixture tests/maps/fixtures/bad_*.yaml (good_tiny.yaml with
one mistake) fails to load with MapDescriptionError naming the file, the dotted key and the
problem; good_tiny.yaml loads. Kit mistakes are checked on edited copies of the real kit."""
import pathlib
import re
import sys
import tempfile
import unittest

ROOT = pathlib.Path(sys.argv[1])
FIX = ROOT / "tests" / "maps" / "fixtures"

from autodrive import maps  # noqa: E402

# fixture: (dotted key, words of the problem)
EXPECTED = {
    "bad_unknown_key.yaml": ("parking_slots[1].colour", "unknown key"),
    "bad_missing_key.yaml": ("spawn.yaw_deg", "missing key"),
    "bad_wrong_type.yaml": ("floor_half_size_m", "expected a number, got str 'two'"),
    "bad_vector_length.yaml": ("boxes[0].size_m", "expected a list of 3 numbers"),
    "bad_overlapping_slots.yaml": ("parking_slots[1]", "slot 's1' overlaps 's0'"),
    "bad_road_gap.yaml": ("roads[0].pieces[1]", "not where the previous piece ends"),
    "bad_stop_line_off_lane.yaml": ("stop_lines[0].centre_m", "off lane 'x_east'"),
    "bad_unknown_surface.yaml": ("terrain_patches[0].surface", "unknown surface 'ice'"),
    "bad_duplicate_name.yaml": ("cones[0].name", "'box_a' is already used by boxes[0].name"),
    "bad_off_floor.yaml": ("cones[0].position_m", "off the floor"),
    "bad_syntax.yaml": ("", "not valid YAML"),
    "bad_reference_tag_id.yaml": ("reference_tags[0].id", "lower ids are the cars' roof tags"),
}


class DescriptionErrors(unittest.TestCase):
    def test_every_bad_fixture_is_covered(self) -> None:
        self.assertEqual(sorted(p.name for p in FIX.glob("bad_*.yaml")), sorted(EXPECTED))

    def test_good_fixture_loads(self) -> None:
        m = maps.load(FIX / "good_tiny.yaml")
        self.assertEqual(m.name, "good_tiny")
        self.assertEqual([s.name for s in m.parking_slots], ["s0", "s1"])

    def test_bad_fixtures_name_file_and_key(self) -> None:
        for name, (key, words) in EXPECTED.items():
            with self.subTest(name):
                with self.assertRaises(maps.MapDescriptionError) as cm:
                    maps.load(FIX / name)
                msg = str(cm.exception)
                self.assertTrue(msg.startswith(str(FIX / name) + ": "), msg)
                if key:
                    self.assertIn(f": {key}: ", msg)
                self.assertIn(words, msg)

    def test_unknown_map_name_lists_the_shipped_ones(self) -> None:
        with self.assertRaises(maps.MapDescriptionError) as cm:
            maps.load("moon_base")
        self.assertIn("moon_base.yaml: no such map description", str(cm.exception))
        self.assertIn("parking_school", str(cm.exception))

    def test_lookups_name_the_map(self) -> None:
        m = maps.load(FIX / "good_tiny.yaml")
        for call, words in (
            (lambda: m.slot("s9"), "no slot 's9'"),
            (lambda: m.slot(2), "no slot 2"),
            (lambda: m.lane("x_north"), "no lane 'x_north'"),
        ):
            with self.assertRaises(maps.MapDescriptionError) as cm:
                call()
            self.assertIn("good_tiny.yaml", str(cm.exception))
            self.assertIn(words, str(cm.exception))

    def test_kit_mistakes(self) -> None:
        kit = (ROOT / "maps" / "kit.yaml").read_text()
        cases = {
            "line_width_m: 0.02": ("line_width_m: -0.02", "marking.line_width_m", "must be > 0"),
            "arc_segments_per_90deg: 24": (
                "arc_segments_per_90deg: 2.5",
                "road.arc_segments_per_90deg",
                "expected a whole number",
            ),
            "snow: {friction: 0.25,": (
                "snow: {mu: 0.25,",
                "surfaces.snow.mu",
                "unknown key",
            ),
            "height_m: 2.5": ("height_m: 2.5\n  roll_deg: 0", "eye_camera.roll_deg", "unknown key"),
        }
        with tempfile.TemporaryDirectory() as tmp:
            path = pathlib.Path(tmp) / "kit.yaml"
            for old, (new, key, words) in cases.items():
                with self.subTest(key):
                    self.assertEqual(len(re.findall(re.escape(old), kit)), 1, old)
                    path.write_text(kit.replace(old, new))
                    with self.assertRaises(maps.MapDescriptionError) as cm:
                        maps.load(FIX / "good_tiny.yaml", kit_path=path)
                    self.assertIn(f"{path}: {key}: ", str(cm.exception))
                    self.assertIn(words, str(cm.exception))


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
