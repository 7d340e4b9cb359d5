"""The demo's command line for the HIL tests (imported from the tests' own folder)."""

import os
import sys
import tempfile

from autodrive.core import channels
from autodrive.core import v2x_ca

_KEY_DIR = None


def use_test_keys(cars=1):
    """A temporary key and certificate per car (and the testbed's SCM, EYE, SIM) in
    $AUTODRIVE_KEY_DIR (inherited by the demo and its children),
    so the tests never read or write the user's own keys."""
    global _KEY_DIR
    if _KEY_DIR is None:
        _KEY_DIR = tempfile.TemporaryDirectory(prefix="hil-keys-")
        os.environ["AUTODRIVE_KEY_DIR"] = _KEY_DIR.name
    v2x_ca.ensure_run_keys([channels.vehicle_name(i) for i in range(1, cars + 1)], lambda _: None)


def demo_command(build, out, port, *options):
    """python -m autodrive.hil.demo, headless, into out, on its own LCM port (test keys)."""
    use_test_keys()
    return [
        sys.executable,
        "-m",
        "autodrive.hil.demo",
        "--build",
        str(build),
        "--out",
        str(out),
        "--headless",
        "--lcm-url",
        f"udpm://239.255.76.67:{port}?ttl=0",
        *options,
    ]


def start_demo_until(build, out, port, marker, *options):
    """The demo started (demo_command) and read until a line with marker: (process, lines)."""
    import subprocess

    demo = subprocess.Popen(
        demo_command(build, out, port, *options),
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    seen = []
    for line in demo.stdout:
        seen.append(line)
        sys.stdout.write(line)
        if marker in line:
            break
    return demo, seen
