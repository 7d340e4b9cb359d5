"""Each of the car's figures is written in one place, vehicle/nigel.params: no other tracked file
outside tests/ spells one by hand (generated files and the map sidecars excepted), and the
generated files in the tree are fresh."""

from __future__ import annotations

import json
import re
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from autodrive.core import vehicle  # noqa: E402
from autodrive.devtools.codegen import tree  # noqa: E402

# Files that may hold the figures: the description itself, files generated from it, tests (which
# state expected values), and the map files generated from the map descriptions (coordinates).
ALLOWED_PREFIXES = ("tests/",)
ALLOWED_FILES = {tree.PARAMS}
ALLOWED_SUFFIXES = (".json", ".xml", ".png", ".jpg", ".pgm")
MIN_SIGNIFICANT_DIGITS = 3  # "0.06" or "1500" would match unrelated numbers; "0.14154" would not


def significant_digits(text: str) -> int:
    return len(text.replace(".", "").replace("-", "").strip("0"))


def distinctive_figures(car: vehicle.Vehicle) -> dict[str, str]:
    """Spelling -> key, for the non-integer figures with enough digits to be recognised."""
    out: dict[str, str] = {}
    for key, value in car.figures.items():
        values = (value,) if isinstance(value, float) else value
        if isinstance(values, str):
            continue
        for v in values:
            text = f"{v:g}"
            # integers and figures of 10 or more (11.8 V) are as likely any measured number
            if (
                float(v).is_integer()
                or abs(v) >= 10
                or significant_digits(text) < MIN_SIGNIFICANT_DIGITS
            ):
                continue
            out.setdefault(text, key)
    return out


def offenders(root: Path, files: list[str], figures: dict[str, str]) -> list[str]:
    pattern = re.compile(
        r"(?<![\d.])("
        + "|".join(re.escape(t) for t in sorted(figures, key=len, reverse=True))
        + r")(?![\d])"
    )
    found = []
    for rel in files:
        if (
            rel in ALLOWED_FILES
            or rel.startswith(ALLOWED_PREFIXES)
            or rel.endswith(ALLOWED_SUFFIXES)
        ):
            continue
        try:
            text = (root / rel).read_text()
        except (UnicodeDecodeError, OSError):
            continue
        for number, line in enumerate(text.splitlines(), start=1):
            for m in pattern.finditer(line):
                found.append(
                    f"{rel}:{number}: {m.group(1)} is {figures[m.group(1)]} ({line.strip()[:90]})"
                )
    return found


def test_figures_written_once_and_generated_files_fresh(root: Path) -> None:
    root = root.resolve()
    car = vehicle.load(root / tree.PARAMS)
    figures = distinctive_figures(car)
    generated = set(tree.render_all(root))
    files = subprocess.run(
        ["git", "ls-files"], cwd=root, check=True, capture_output=True, text=True
    ).stdout.split()
    files = [f for f in files if f not in generated]
    errors = offenders(root, files, figures)

    # The check can fail: a planted copy of the wheelbase is found.
    with tempfile.TemporaryDirectory() as tmp:
        planted = Path(tmp) / "planted.cpp"
        planted.write_text(f"const double L = {car.number('wheelbase_m'):g};  // [m]\n")
        if not offenders(Path(tmp), ["planted.cpp"], figures):
            errors.append("self-check: a planted wheelbase was not found")

    for rel, text in tree.render_all(root).items():
        path = root / rel
        if not path.is_file() or path.read_text() != text:
            errors.append(f"{rel}: stale or missing generated file (run tools/gen-docs)")

    print(
        f"{len(figures)} distinctive figures checked in {len(files)} files: {len(errors)} problem(s)"
    )
    assert not errors, "\n".join(errors)


def test_the_leak_check_options_are_written_once(root: Path) -> None:
    """LeakSanitizer's options are one CMake variable (cmake/AutodriveSanitizers.cmake); the asan
    test preset's copy (a preset cannot read a CMake variable) says the same."""
    root = root.resolve()
    module = (root / "cmake" / "AutodriveSanitizers.cmake").read_text()
    m = re.search(r'^set\(AUTODRIVE_LSAN_OPTIONS "([^"]+)"\)', module, re.MULTILINE)
    assert m, "cmake/AutodriveSanitizers.cmake sets no AUTODRIVE_LSAN_OPTIONS"
    presets = json.loads((root / "CMakePresets.json").read_text())
    asan = [p for p in presets["testPresets"] if p["name"] == "asan"][0]
    copy = asan["environment"]["LSAN_OPTIONS"].replace("${sourceDir}", "${PROJECT_SOURCE_DIR}")
    assert copy == m.group(1), f"CMakePresets.json's asan LSAN_OPTIONS {copy} != {m.group(1)}"
    files = subprocess.run(
        ["git", "ls-files", "*CMakeLists.txt", "*.cmake"],
        cwd=root, check=True, capture_output=True, text=True,
    ).stdout.split()  # fmt: skip
    spelled = [f for f in files if "lsan.supp:" in (root / f).read_text()]
    assert spelled == ["cmake/AutodriveSanitizers.cmake"], f"LSAN options spelled in {spelled}"
