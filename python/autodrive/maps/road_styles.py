"""Road surface variants for domain randomisation (issue 38): a seeded draw of how the kit's
lines are painted (the centre line's and the edge lines' colour, dashed or solid) and of the
asphalt's tone, and a texture folder painted with it for `autodrive-sim --texture-dir`.

Why: a two-lane loop shows its curves with the dashed centre line on the inside in one lane
and on the outside in the other. A model recorded in one lane only learns which line is
which; one recorded on varied markings has to learn the lane's geometry instead."""

from __future__ import annotations

import json
import random
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from autodrive.maps import textures
from autodrive.maps.loader import MAPS_DIR, load, load_kit
from autodrive.maps.model import Kit, Vec3

KIT_SHARE = 0.35  # the share of draws that keep the kit's own lines (its tone still varies)
ASPHALT_TONE = (0.7, 1.45)  # the asphalt's brightness relative to the kit's, uniform
STYLE_FILE = "road_style.json"  # in a texture folder: the style it was painted with


@dataclass(frozen=True)
class RoadStyle:
    """One draw: the centre line's and the edge lines' colour ("centre": the kit's centre
    colour, "line": its line colour) and whether each is dashed, and the asphalt's tone."""

    centre_colour: str = "centre"
    centre_dashed: bool = True
    edge_colour: str = "line"
    edge_dashed: bool = False
    asphalt_tone: float = 1.0

    def is_kit(self) -> bool:
        return self == RoadStyle()

    def marking(self, kit: Kit) -> textures.Marking:
        tk = kit.tiles
        rgb = {"centre": tk.centre_rgb, "line": tk.line_rgb}
        a = tk.asphalt_rgb
        tone: Vec3 = (
            min(255.0, a[0] * self.asphalt_tone),
            min(255.0, a[1] * self.asphalt_tone),
            min(255.0, a[2] * self.asphalt_tone),
        )
        return textures.Marking(
            centre_rgb=rgb[self.centre_colour],
            centre_dashed=self.centre_dashed,
            edge_rgb=rgb[self.edge_colour],
            edge_dashed=self.edge_dashed,
            asphalt_rgb=tuple(round(c) for c in tone),  # type: ignore[arg-type]
        )


def draw(seed: int) -> RoadStyle:
    """The style of a recording with this seed (the same seed, the same style)."""
    rng = random.Random(f"road-style-{seed}")
    tone = round(rng.uniform(*ASPHALT_TONE), 3)
    if rng.random() < KIT_SHARE:
        return RoadStyle(asphalt_tone=tone)
    return RoadStyle(
        centre_colour=rng.choice(("centre", "line")),
        centre_dashed=rng.random() < 0.5,
        edge_colour=rng.choice(("line", "centre")),
        edge_dashed=rng.random() < 0.5,
        asphalt_tone=tone,
    )


def write_texture_dir(
    map_name: str, style: RoadStyle, out: Path, maps_dir: Path = MAPS_DIR
) -> Path:
    """Paints map_name's tile textures with style into out/textures/ and links every other
    texture of maps_dir/textures there, so that `autodrive-sim --texture-dir out` finds all of
    the map's files. Returns out. out/road_style.json records the style."""
    m = load(maps_dir / f"{map_name}.yaml", maps_dir / "kit.yaml")
    kit = load_kit(maps_dir / "kit.yaml")
    tex = out / textures.DIR_NAME
    tex.mkdir(parents=True, exist_ok=True)
    painted = textures.tile_textures(kit, {(t.type, t.lanes) for t in m.tiles}, style.marking(kit))
    for name, png in painted.items():
        (tex / f"{name}.png").write_bytes(png)
    for src in sorted((maps_dir / textures.DIR_NAME).glob("*.png")):
        dst = tex / src.name
        if not dst.exists():
            dst.symlink_to(src.resolve())
    (out / STYLE_FILE).write_text(json.dumps(asdict(style), indent=2) + "\n")
    return out


def as_record(style: RoadStyle) -> dict[str, Any]:
    """The style as a dataset manifest records it."""
    return dict(asdict(style), kit=style.is_kit())
