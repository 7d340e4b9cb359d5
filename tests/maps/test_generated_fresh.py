"""maps.generated_fresh: the committed maps/<map>.xml and .json are what tools/gen-maps writes
from the descriptions, and --check notices a stale or missing file (in a copy of the folder)."""
import pathlib
import shutil
import subprocess
import sys
import tempfile
import unittest

ROOT = pathlib.Path(sys.argv[1])
GEN = ROOT / "tools" / "gen-maps"
MAPS = ROOT / "sim" / "mujoco_hil" / "maps"


def gen(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, str(GEN), *args], capture_output=True, text=True, timeout=60
    )


class GeneratedFresh(unittest.TestCase):
    def test_committed_files_are_fresh(self) -> None:
        r = gen("--check")
        self.assertEqual(r.returncode, 0, r.stderr)
        from autodrive_tools import maps

        names = maps.names()
        self.assertIn("parking_school", names)
        self.assertIn("driving_school", names)
        for n in names:  # every description has both generated files
            self.assertTrue((MAPS / f"{n}.xml").is_file(), n)
            self.assertTrue((MAPS / f"{n}.json").is_file(), n)

    def test_check_names_stale_and_missing_files_then_regenerates(self) -> None:
        with tempfile.TemporaryDirectory() as tmp:
            d = pathlib.Path(tmp) / "maps"
            shutil.copytree(MAPS, d)
            xml = d / "parking_school.xml"
            xml.write_text(xml.read_text().replace('"box_a"', '"box_z"'))
            (d / "driving_school.json").unlink()
            r = gen("--check", "--dir", str(d))
            self.assertEqual(r.returncode, 1, r.stderr)
            self.assertIn("parking_school.xml is stale", r.stderr)
            self.assertIn("driving_school.json is stale", r.stderr)
            self.assertNotIn("parking_school.json", r.stderr)
            r = gen("--dir", str(d))
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertEqual(xml.read_text(), (MAPS / "parking_school.xml").read_text())
            self.assertEqual(gen("--check", "--dir", str(d)).returncode, 0)
            # a description change is a stale file until regenerated
            y = d / "parking_school.yaml"
            y.write_text(y.read_text().replace("[1.5, 0.0], size_m", "[1.4, 0.0], size_m"))
            r = gen("--check", "--dir", str(d))
            self.assertEqual(r.returncode, 1)
            self.assertIn("parking_school.xml is stale", r.stderr)
            self.assertIn("parking_school.json is stale", r.stderr)

    def test_bad_description_exits_2_naming_it(self) -> None:
        with tempfile.TemporaryDirectory() as tmp:
            d = pathlib.Path(tmp)
            shutil.copy(MAPS / "kit.yaml", d)
            shutil.copy(ROOT / "tests" / "maps" / "fixtures" / "bad_wrong_type.yaml", d)
            r = gen("--check", "--dir", str(d))
            self.assertEqual(r.returncode, 2)
            self.assertIn("bad_wrong_type.yaml: floor_half_size_m", r.stderr)

    def test_help(self) -> None:
        r = gen("--help")
        self.assertEqual(r.returncode, 0)
        self.assertIn("--check", r.stdout)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
