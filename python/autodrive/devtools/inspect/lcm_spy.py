"""tools/lcm-spy: LCM's own spy (Java) with our message types decoded.

Debian's lcm-spy launcher passes -Xincgc, which Java 17 refuses, and knows none of our types.
This builds the types into a jar (lcm-gen --java, javac, jar: Debian's liblcm-bin, liblcm-java
and JDK), kept in <build>/lcm_types/java and rebuilt when a .lcm file is newer, and starts the
spy with lcm.jar, jchart2d.jar and that jar on its class path (the spy finds the types there).
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from autodrive.core import channels
from autodrive.core.settings import RELEASE_BUILD, settings

LCM_JAR = Path("/usr/share/java/lcm.jar")
JCHART_JAR = Path("/usr/share/java/jchart2d.jar")
TYPES_DIR = settings().lcm_type_dir
SPY_CLASS = "lcm.spy.Spy"


class SpyError(RuntimeError):
    """A missing tool or a failed type build; the message names it."""


def _need(path: Path, package: str) -> None:
    if not path.exists():
        raise SpyError(f"{path} is missing (Debian package {package}: run tools/setup)")


def _run(argv: list[str]) -> None:
    r = subprocess.run(argv, capture_output=True, text=True)
    if r.returncode != 0:
        raise SpyError(f"{argv[0]} failed: {(r.stderr or r.stdout).strip()[-800:]}")


def types_jar(build: Path) -> Path:
    """The jar of our LCM types for this build, built if missing or older than a .lcm file."""
    _need(LCM_JAR, "liblcm-java")
    for tool, package in (("lcm-gen", "liblcm-bin"), ("javac", "default-jdk-headless")):
        if shutil.which(tool) is None:
            raise SpyError(f"{tool} is missing (Debian package {package}: run tools/setup)")
    sources = sorted(TYPES_DIR.glob("*_t.lcm"))
    jar = build.resolve() / "lcm_types" / "java" / "autodrive_types.jar"
    if jar.is_file() and all(jar.stat().st_mtime >= s.stat().st_mtime for s in sources):
        return jar
    jar.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="lcm-java-") as tmp:
        src, classes = Path(tmp) / "src", Path(tmp) / "classes"
        _run(["lcm-gen", "--java", "--jpath", str(src), *map(str, sources)])
        java_files = [str(f) for f in sorted(src.rglob("*.java"))]
        _run(["javac", "-nowarn", "-cp", str(LCM_JAR), "-d", str(classes), *java_files])
        _run(["jar", "cf", str(jar), "-C", str(classes), "."])
    return jar


def spy_command(build: Path, lcm_url: str) -> list[str]:
    """The java command line that starts the spy on lcm_url with our types."""
    _need(JCHART_JAR, "libjchart2d-java")
    class_path = os.pathsep.join(str(p) for p in (LCM_JAR, JCHART_JAR, types_jar(build)))
    # -Djava.net.preferIPv4Stack: LCM's UDP multicast is IPv4.
    java = ["java", "-Djava.net.preferIPv4Stack=true", "-Xmx256m", "-cp", class_path]
    return [*java, SPY_CLASS, "--lcm-url", lcm_url]


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="tools/lcm-spy",
        description="LCM's spy with the project's message types decoded (needs a display).",
    )
    p.add_argument("--build", type=Path, default=RELEASE_BUILD, help="host build dir (for its jar)")
    p.add_argument("--lcm-url", default=channels.load().url_default, help="LCM URL to watch")
    p.add_argument("--print-command", action="store_true", help="print the java command and exit")
    args = p.parse_args(argv)
    try:
        cmd = spy_command(args.build, args.lcm_url)
    except SpyError as e:
        print(f"lcm-spy: {e}", file=sys.stderr)
        return 2
    if args.print_command:
        print(" ".join(cmd))
        return 0
    if not os.environ.get("DISPLAY"):
        print(
            "lcm-spy: no DISPLAY: the spy is a window (try xvfb-run for a headless check)",
            file=sys.stderr,
        )
        return 2
    return subprocess.call(cmd)


if __name__ == "__main__":
    sys.exit(main())
