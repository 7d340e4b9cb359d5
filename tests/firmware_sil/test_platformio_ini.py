"""platformio.ini checked through PlatformIO's own parser: no warnings, the two online Nano envs
(PlatformIO's atmelavr, which needs its registry) and the two offline ones (the platform in
firmware/nano/pio), src/lib dirs that exist and hold the firmware."""
import os
from pathlib import Path

import pytest

from platformio.project.config import ProjectConfig


def test_platformio_ini_through_platformio(root: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    root = os.path.abspath(root)
    monkeypatch.chdir(
        root
    )  # PlatformIO resolves the dirs against the project dir, which is the cwd
    cfg = ProjectConfig(os.path.join(root, "platformio.ini"))
    cfg.validate()
    assert cfg.warnings == [], f"platformio.ini warnings: {cfg.warnings}"
    envs = cfg.envs()
    want = ["nano_offline", "nano_offline_new", "nanoatmega328", "nanoatmega328new"]
    assert sorted(envs) == want, f"envs: {envs}"
    for env in ("nano_offline", "nano_offline_new"):
        platform = cfg.get(f"env:{env}", "platform")
        assert platform == "symlink://firmware/nano/pio", f"{env}: platform {platform}"
        assert cfg.get(f"env:{env}", "board") == "nigel_nano", f"{env}: board"
    speed = cfg.get("env:nano_offline_new", "board_upload.speed")
    assert str(speed) == "115200", f"nano_offline_new: upload speed {speed}"
    for env in ("nanoatmega328", "nanoatmega328new"):
        assert cfg.get(f"env:{env}", "board") == env, f"{env}: board"
        assert cfg.get(f"env:{env}", "platform") == "atmelavr", f"{env}: platform"
        assert cfg.get(f"env:{env}", "framework") == ["arduino"], f"{env}: framework"
    src = cfg.get("platformio", "src_dir")
    lib = cfg.get("platformio", "lib_dir")
    assert os.path.samefile(src, os.path.join(root, "firmware/nano/hal_avr")), f"src_dir {src}"
    assert os.path.samefile(lib, os.path.join(root, "firmware/nano/core")), f"lib_dir {lib}"
    main_cpp = open(os.path.join(src, "main.cpp")).read()
    assert "void setup()" in main_cpp and "void loop()" in main_cpp, "src has no Arduino sketch"
    for module in ("nano_core", "protocol", "encoder"):
        assert os.path.isdir(os.path.join(lib, module)), f"lib module {module} missing"
    print("platformio.ini ok:", ", ".join(envs))
