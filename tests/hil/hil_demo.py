"""The demo's command line for the HIL tests (imported from the tests' own folder)."""

import sys


def demo_command(build, out, port, *options):
    """python -m autodrive_tools.demo, headless, into out, on its own LCM port."""
    return [
        sys.executable,
        "-m",
        "autodrive_tools.demo",
        "--build",
        str(build),
        "--out",
        str(out),
        "--headless",
        "--lcm-url",
        f"udpm://239.255.76.67:{port}?ttl=0",
        *options,
    ]
