"""maps.road_styles: the domain randomisation's road styles are drawn the same for a seed, vary
across seeds, keep the kit's own textures byte for byte, and a painted texture folder holds every
texture the map names (the styled tiles painted, the rest linked)."""
import json
import pathlib
import re

from autodrive.maps import road_styles, textures
from autodrive.maps.loader import MAPS_DIR, load_kit
from pyhelpers import REPO_ROOT


def test_draw_is_seeded_and_varies():
    assert road_styles.draw(11) == road_styles.draw(11)
    drawn = {road_styles.draw(s) for s in range(1, 41)}
    assert len(drawn) > 20
    assert any(s.edge_dashed and not s.centre_dashed for s in drawn)  # the other lane's look
    assert all(
        road_styles.ASPHALT_TONE[0] <= s.asphalt_tone <= road_styles.ASPHALT_TONE[1] for s in drawn
    )


def test_kit_style_paints_the_committed_textures():
    kit = load_kit(MAPS_DIR / "kit.yaml")
    painted = textures.tile_textures(
        kit, {("curve", 2), ("tee", 2)}, road_styles.RoadStyle().marking(kit)
    )
    for name, png in painted.items():
        assert png == (MAPS_DIR / "textures" / f"{name}.png").read_bytes(), name


def test_texture_dir_holds_every_texture_of_the_map(tmp_path: pathlib.Path):
    style = road_styles.RoadStyle(
        centre_colour="line",
        centre_dashed=False,
        edge_colour="centre",
        edge_dashed=True,
        asphalt_tone=1.3,
    )
    out = road_styles.write_texture_dir("driving_school", style, tmp_path / "road")
    xml = (REPO_ROOT / "maps" / "driving_school.xml").read_text()
    for f in re.findall(r'file="(textures/[^"]+)"', xml):
        assert (out / f).is_file(), f
    curve = (out / "textures" / "tile_curve_2.png").read_bytes()
    assert curve != (MAPS_DIR / "textures" / "tile_curve_2.png").read_bytes()
    assert json.loads((out / road_styles.STYLE_FILE).read_text())["edge_dashed"] is True
