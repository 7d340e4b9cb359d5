"""maps.generated_fresh: the committed maps/<map>.xml and .json and the textures in
maps/textures/ are what tools/gen-maps writes from the descriptions (byte for byte), and --check
notices a stale or missing file (in a copy of the folder)."""
import pathlib
import re
import shutil
import subprocess
import tempfile

from pyhelpers import REPO_ROOT

ROOT = REPO_ROOT
GEN = ROOT / "tools" / "gen-maps"
MAPS = ROOT / "maps"


def gen(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([str(GEN), *args], capture_output=True, text=True, timeout=60)


def test_committed_files_are_fresh() -> None:
    r = gen("--check")
    assert r.returncode == 0, r.stderr
    from autodrive import maps

    names = maps.names()
    for want in ("parking_school", "driving_school", "intersection_school", "tiny_town"):
        assert want in names
    for n in names:  # every description has both generated files
        assert (MAPS / f"{n}.xml").is_file(), n
        assert (MAPS / f"{n}.json").is_file(), n
    # every texture a map names is committed, and nothing else is in textures/
    used = set()
    for n in names:
        used |= set(re.findall(r'file="textures/([^"]+)"', (MAPS / f"{n}.xml").read_text()))
    have = {p.name for p in (MAPS / "textures").iterdir()}
    assert used == have
    total = sum((MAPS / "textures" / f).stat().st_size for f in have)
    assert total < 400_000, "textures should stay small"


def test_textures_are_regenerated_byte_for_byte() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        d = pathlib.Path(tmp) / "maps"
        shutil.copytree(MAPS, d)
        tex = d / "textures" / "tile_cross_2.png"
        tex.write_bytes(tex.read_bytes()[:-20])
        (d / "textures" / "sign_stop.png").unlink()
        r = gen("--check", "--dir", str(d))
        assert r.returncode == 1, r.stderr
        assert "tile_cross_2.png is stale" in r.stderr
        assert "sign_stop.png is stale" in r.stderr
        assert "tile_straight_2.png" not in r.stderr
        r = gen("--dir", str(d))
        assert r.returncode == 0, r.stderr
        for name in ("tile_cross_2.png", "sign_stop.png"):
            assert (d / "textures" / name).read_bytes() == (MAPS / "textures" / name).read_bytes()
        # a kit change repaints the textures it touches
        kit = d / "kit.yaml"
        kit.write_text(
            kit.read_text().replace("asphalt_rgb: [62, 62, 66]", "asphalt_rgb: [60, 60, 66]")
        )
        r = gen("--check", "--dir", str(d))
        assert r.returncode == 1
        assert "tile_cross_2.png is stale" in r.stderr
        assert "sign_stop.png" not in r.stderr


def test_check_names_stale_and_missing_files_then_regenerates() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        d = pathlib.Path(tmp) / "maps"
        shutil.copytree(MAPS, d)
        xml = d / "parking_school.xml"
        xml.write_text(xml.read_text().replace('"box_a"', '"box_z"'))
        (d / "driving_school.json").unlink()
        r = gen("--check", "--dir", str(d))
        assert r.returncode == 1, r.stderr
        assert "parking_school.xml is stale" in r.stderr
        assert "driving_school.json is stale" in r.stderr
        assert "parking_school.json" not in r.stderr
        r = gen("--dir", str(d))
        assert r.returncode == 0, r.stderr
        assert xml.read_text() == (MAPS / "parking_school.xml").read_text()
        assert gen("--check", "--dir", str(d)).returncode == 0
        # a description change is a stale file until regenerated
        y = d / "parking_school.yaml"
        y.write_text(y.read_text().replace("[1.5, 0.0], size_m", "[1.4, 0.0], size_m"))
        r = gen("--check", "--dir", str(d))
        assert r.returncode == 1
        assert "parking_school.xml is stale" in r.stderr
        assert "parking_school.json is stale" in r.stderr


def test_bad_description_exits_2_naming_it() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        d = pathlib.Path(tmp)
        shutil.copy(MAPS / "kit.yaml", d)
        shutil.copy(ROOT / "tests" / "maps" / "fixtures" / "bad_wrong_type.yaml", d)
        r = gen("--check", "--dir", str(d))
        assert r.returncode == 2
        assert "bad_wrong_type.yaml: floor_half_size_m" in r.stderr


def test_help() -> None:
    r = gen("--help")
    assert r.returncode == 0
    assert "--check" in r.stdout
