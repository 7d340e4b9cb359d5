"""GNU Octave with the MATLAB/Octave toolbox (octave/+autodrive) for tests and benches: the jar
of our LCM types (built at build time by lcm-gen --java and javac, the same jar tools/lcm-spy
uses; never committed) and `octave` run on a script with the toolbox on its path.

`python -m autodrive.apis.octave --jar [--build DIR]` builds the jar and prints its path."""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
from pathlib import Path

from autodrive.core.proc import third_party_env
from autodrive.core.settings import settings
from autodrive.devtools.inspect.lcm_spy import types_jar


def toolbox_dir() -> Path:
    return settings().root / "octave"


def environment(build: Path, url: str) -> dict[str, str]:
    """The environment an Octave script of the toolbox runs in: the bus and the types jar."""
    jar = str(types_jar(build))
    return dict(third_party_env(), AUTODRIVE_LCM_URL=url, AUTODRIVE_TYPES_JAR=jar)  # a JVM


def command(script: str) -> list[str]:
    """octave on a script (Octave code), the toolbox on its path. RuntimeError without octave."""
    exe = shutil.which("octave-cli") or shutil.which("octave")
    if exe is None:
        raise RuntimeError("octave not found: install Debian's octave (tools/setup does)")
    code = f"addpath('{toolbox_dir()}'); {script}"
    return [exe, "--no-gui", "--no-window-system", "--norc", "--quiet", "--eval", code]


def run(build: Path, url: str, script: str, timeout_s: float) -> subprocess.CompletedProcess[str]:
    """Runs script to its end (timeout_s: a hang guard); its output as text."""
    return subprocess.run(
        command(script), env=environment(build, url), capture_output=True, text=True,
        timeout=timeout_s,
    )  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m autodrive.apis.octave", description=__doc__)
    p.add_argument("--jar", action="store_true", help="build the types jar, print its path")
    p.add_argument("--build", type=Path, default=settings().preset_build("release"))
    a = p.parse_args(argv)
    if not a.jar:
        p.error("nothing to do (--jar)")
    print(types_jar(a.build))
    return 0


if __name__ == "__main__":
    sys.exit(main())
