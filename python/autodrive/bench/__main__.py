"""python -m autodrive.bench <suite> [suite options]: runs one benchmark suite."""

from __future__ import annotations

import importlib
import sys

from autodrive.bench import SUITES

USAGE = f"""usage: tools/bench <suite> [suite options]
suites: {' '.join(SUITES)}
Builds the release preset, runs the suite, prints its figures; the last line is JSON.
Suite options: tools/bench <suite> --help."""


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if not argv or argv[0] in ("-h", "--help"):
        print(USAGE)
        return 0 if argv else 2
    if argv[0] == "--list":
        print(" ".join(SUITES))
        return 0
    suite = argv[0]
    if suite not in SUITES:
        print(
            f"[bench] ERROR: unknown suite '{suite}' (suites: {' '.join(SUITES)})", file=sys.stderr
        )
        return 2
    module = importlib.import_module(f"{__package__}.{suite}")
    code: int = module.main(argv[1:])
    return code


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
