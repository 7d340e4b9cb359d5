"""tools/gen-maps: regenerates every map's MJCF scene and JSON sidecar from its description."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from autodrive.maps import mjcf, reftags, sidecar, textures
from autodrive.maps.loader import MAPS_DIR, load, load_kit, names
from autodrive.maps.model import MapDescriptionError


def outputs(name: str, maps_dir: Path = MAPS_DIR) -> dict[Path, str]:
    """The generated files of one map (beside its description) and their content."""
    m = load(maps_dir / f"{name}.yaml", maps_dir / "kit.yaml")
    return {
        maps_dir / f"{name}.xml": mjcf.generate(m),
        maps_dir / f"{name}.json": sidecar.generate(m),
    }


def texture_outputs(maps_dir: Path = MAPS_DIR) -> dict[Path, bytes]:
    """The textures every map in the folder uses (one per tile type and lane count, one per sign
    kind, one per reference tag) in maps_dir/textures, and their PNG bytes."""
    tile_keys: set[tuple[str, int]] = set()
    sign_keys: set[tuple[str, str]] = set()
    tag_ids: set[int] = set()
    for name in names(maps_dir):
        m = load(maps_dir / f"{name}.yaml", maps_dir / "kit.yaml")
        tile_keys |= {(t.type, t.lanes) for t in m.tiles}
        sign_keys |= {
            (s.kind, textures.sign_texture_name(s.kind, s.speed_limit_m_s))
            for s in m.placed_signs()
        }
        tag_ids |= {t.id for t in m.reference_tags}
    kit = load_kit(maps_dir / "kit.yaml")
    out = textures.generate(kit, tile_keys, sign_keys)
    out.update({reftags.texture_name(i): reftags.png(i) for i in sorted(tag_ids)})
    return {maps_dir / textures.DIR_NAME / f"{n}.png": b for n, b in out.items()}


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="tools/gen-maps",
        description="Regenerate maps/<map>.xml (MJCF) and <map>.json (sidecar for "
        "C/C++ readers) from <map>.yaml and kit.yaml, for every map, and the textures the maps "
        "use (maps/textures/*.png: one per tile type and lane count, one per sign kind).",
    )
    p.add_argument(
        "--check",
        action="store_true",
        help="write nothing; exit 1 naming every generated file that is stale or missing",
    )
    p.add_argument(
        "--dir",
        type=Path,
        default=MAPS_DIR,
        help="folder with kit.yaml and the map descriptions (default: %(default)s)",
    )
    args = p.parse_args(argv)
    stale = []
    try:
        if not (args.dir / "kit.yaml").is_file():
            raise MapDescriptionError(f"{args.dir}: no kit.yaml in this folder")
        files: dict[Path, bytes] = {}
        for name in names(args.dir):
            files.update({p: t.encode() for p, t in outputs(name, args.dir).items()})
        files.update(texture_outputs(args.dir))
        for path, data in files.items():
            old = path.read_bytes() if path.is_file() else None
            if old == data:
                continue
            if args.check:
                stale.append(path)
            else:
                path.parent.mkdir(parents=True, exist_ok=True)
                path.write_bytes(data)
                print(f"gen-maps: wrote {path}")
    except MapDescriptionError as err:
        print(f"gen-maps: {err}", file=sys.stderr)
        return 2
    for path in stale:
        print(f"gen-maps: {path} is stale: run tools/gen-maps and commit it", file=sys.stderr)
    return 1 if stale else 0


if __name__ == "__main__":
    sys.exit(main())
