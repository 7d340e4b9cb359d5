"""tools/keys: creates and checks the per-car command keys (32 random bytes, 64 hex digits,
mode 0600) that sign <VEH>_COMMAND. Default place: autodrive.core.command_auth.default_key_path.

Also the testbed certificate authority: tools/keys ca init | issue | revoke | show
(autodrive.core.v2x_ca). CLI: tools/keys --help (python -m autodrive.core.keys)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from autodrive.core import channels
from autodrive.core.command_auth import create_key, default_key_path, load_key


CA_ACTIONS = ("ca", "issue", "revoke", "show", "testbed")


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if any(a in CA_ACTIONS for a in argv[:3]):  # the testbed CA (autodrive.core.v2x_ca)
        from autodrive.core import v2x_ca

        return v2x_ca.main(argv)
    p = argparse.ArgumentParser(
        prog="tools/keys",
        description="Create or check a car's command key (signs <VEH>_COMMAND; the runtime's "
        "bridge drops commands without a valid signature). Default file: "
        "$AUTODRIVE_KEY_DIR/<VEH>.key, else ~/.config/autodrive/keys/<VEH>.key. The testbed "
        "certificate authority: tools/keys ca init | issue | revoke | show | testbed (each with --help).",
    )
    p.add_argument("action", choices=("create", "check", "path"), help="what to do")
    p.add_argument("vehicles", nargs="*", help=f"car names (default: {channels.vehicle_name(1)})")
    p.add_argument("--file", type=Path, help="the key file (one car only)")
    p.add_argument("--force", action="store_true", help="create: replace an existing key")
    p.add_argument(
        "--if-missing", action="store_true", help="create: keep an existing key, no error"
    )
    args = p.parse_intermixed_args(argv)
    vehicles = args.vehicles or [channels.vehicle_name(1)]
    if args.file is not None and len(vehicles) != 1:
        p.error("--file goes with exactly one car")
    status = 0
    for veh in vehicles:
        path = args.file or default_key_path(veh)
        try:
            if args.action == "path":
                print(path)
            elif args.action == "create":
                if args.if_missing and path.exists():
                    load_key(path)  # an existing key must still be usable
                    print(f"[keys] {veh}: key present at {path}")
                else:
                    create_key(path, args.force)
                    print(f"[keys] {veh}: created {path} (mode 0600)")
            else:
                load_key(path)
                print(f"[keys] {veh}: {path} ok")
        except ValueError as e:
            print(f"[keys] ERROR: {e}", file=sys.stderr)
            status = 1
    return status


if __name__ == "__main__":
    sys.exit(main())
