"""maps.description_errors: each fixture tests/maps/fixtures/bad_*.yaml (good_tiny.yaml with
one mistake) fails to load with MapDescriptionError naming the file, the dotted key and the
problem; good_tiny.yaml loads. Kit mistakes are checked on edited copies of the real kit."""
import pathlib
import re
import tempfile

import pytest

from pyhelpers import REPO_ROOT

ROOT = REPO_ROOT
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


def test_every_bad_fixture_is_covered() -> None:
    assert sorted(p.name for p in FIX.glob("bad_*.yaml")) == sorted(EXPECTED)


def test_good_fixture_loads() -> None:
    m = maps.load(FIX / "good_tiny.yaml")
    assert m.name == "good_tiny"
    assert [s.name for s in m.parking_slots] == ["s0", "s1"]


def test_bad_fixtures_name_file_and_key() -> None:
    for name, (key, words) in EXPECTED.items():
        with pytest.raises(maps.MapDescriptionError) as cm:
            maps.load(FIX / name)
        msg = str(cm.value)
        assert msg.startswith(str(FIX / name) + ": "), msg
        if key:
            assert f": {key}: " in msg
        assert words in msg


def test_unknown_map_name_lists_the_shipped_ones() -> None:
    with pytest.raises(maps.MapDescriptionError) as cm:
        maps.load("moon_base")
    assert "moon_base.yaml: no such map description" in str(cm.value)
    assert "parking_school" in str(cm.value)


def test_lookups_name_the_map() -> None:
    m = maps.load(FIX / "good_tiny.yaml")
    for call, words in (
        (lambda: m.slot("s9"), "no slot 's9'"),
        (lambda: m.slot(2), "no slot 2"),
        (lambda: m.lane("x_north"), "no lane 'x_north'"),
    ):
        with pytest.raises(maps.MapDescriptionError) as cm:
            call()
        assert "good_tiny.yaml" in str(cm.value)
        assert words in str(cm.value)


def test_kit_mistakes() -> None:
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
            assert len(re.findall(re.escape(old), kit)) == 1, old
            path.write_text(kit.replace(old, new))
            with pytest.raises(maps.MapDescriptionError) as cm:
                maps.load(FIX / "good_tiny.yaml", kit_path=path)
            assert f"{path}: {key}: " in str(cm.value)
            assert words in str(cm.value)
