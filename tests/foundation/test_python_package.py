"""The Python distribution finds repository data through its settings object only: no module
of python/autodrive builds a path from `__file__`; AUTODRIVE_ROOT wins and a wrong one is an
error naming what is missing; the editable install's source tree is found without it."""

import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(os.environ["AUTODRIVE_ROOT"]).resolve()
PACKAGE = ROOT / "python" / "autodrive"
FORBIDDEN = "__" + "file__"  # spelled apart so that this file does not match its own grep


def test_no_path_from_file() -> None:
    hits = [
        f"{p.relative_to(ROOT)}:{n}: {line.strip()}"
        for p in sorted(PACKAGE.rglob("*.py"))
        for n, line in enumerate(p.read_text().splitlines(), 1)
        if FORBIDDEN in line
    ]
    why = "paths from the module's location (use autodrive.core.settings):"
    assert not hits, "\n".join([why, *hits])


def settings_root(env: dict[str, str], cwd: str) -> subprocess.CompletedProcess[str]:
    code = "from autodrive.core.settings import settings; print(settings().root)"
    return subprocess.run(
        [sys.executable, "-c", code], env=env, cwd=cwd, capture_output=True, text=True, timeout=60
    )


def test_root_from_environment() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        env = {**os.environ, "AUTODRIVE_ROOT": str(ROOT)}
        r = settings_root(env, tmp)
        assert r.returncode == 0 and Path(r.stdout.strip()) == ROOT, r.stdout + r.stderr
        env["AUTODRIVE_ROOT"] = tmp  # no vehicle/ nor lcm_types/ there
        r = settings_root(env, tmp)
        assert r.returncode != 0, r.stdout
        for text in ("AUTODRIVE_ROOT", tmp, "vehicle/nigel.params", "lcm_types/channels.yaml"):
            assert text in r.stderr, (text, r.stderr)


def test_root_from_editable_install() -> None:
    env = {k: v for k, v in os.environ.items() if k not in ("AUTODRIVE_ROOT", "PYTHONPATH")}
    with tempfile.TemporaryDirectory() as tmp:  # outside the tree: only the install can tell
        r = settings_root(env, tmp)
    assert r.returncode == 0 and Path(r.stdout.strip()) == ROOT, r.stdout + r.stderr
    print(f"editable install's repository: {r.stdout.strip()}")
