"""autodrive-scm: the Smart City Manager server, and its user administration.

    autodrive-scm --map tiny_town [--db URL] [--host H] [--port N] [--lcm-url URL]
                  [--vehicles NIGEL1,NIGEL2,NIGEL3] [--history-hz HZ] [--clock wall|sim]
                  [--build DIR]
    autodrive-scm user add NAME --role operator|viewer [--db URL] [--password-stdin]

Prints "SCM ready http://HOST:PORT/" on stdout once it serves."""

from __future__ import annotations

import argparse
import contextlib
import getpass
import signal
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import uvicorn

from autodrive.core import channels
from autodrive.core.v2x_cert import CertificateError
from autodrive import maps
from autodrive.scm.core.config import (
    DEFAULT_HOST,
    DEFAULT_MAP,
    DEFAULT_PORT,
    default_url,
    find_build,
)
from autodrive.scm.core.db import DatabaseError, migrate, open_engine, sessions
from autodrive.scm.core.security import UserError, add_user


def parse_serve(argv: list[str]) -> argparse.Namespace:
    p = argparse.ArgumentParser(
        prog="autodrive-scm",
        description="Smart City Manager: vehicles, traffic lights, signs and an event log in a "
        "database; light control; V2I advisories on LCM; a REST/WebSocket API (/docs) and a web "
        "app. Users: 'autodrive-scm user add NAME --role operator'.",
    )
    p.add_argument("--map", default=DEFAULT_MAP, help="map name or description YAML")
    p.add_argument("--db", default=default_url(), help="sqlite:///PATH or postgresql://...")
    p.add_argument("--host", default=DEFAULT_HOST)
    p.add_argument("--port", type=int, default=DEFAULT_PORT)
    p.add_argument("--lcm-url", default=channels.load().url_default)
    p.add_argument(
        "--vehicles",
        default="",
        help="cars to advise, e.g. NIGEL1,NIGEL2,NIGEL3 " "(empty: every car whose pose is seen)",
    )
    p.add_argument(
        "--history-hz",
        type=float,
        default=10.0,
        help="pose history kept per car [Hz] (0: every pose)",
    )
    p.add_argument("--advisory-hz", type=float, default=10.0, help="V2I advisories per car [Hz]")
    p.add_argument(
        "--clock",
        choices=("wall", "sim"),
        default="wall",
        help="the lights' clock (yellow, all-red, programs, actuated holds): this machine's "
        "(a real town), or the simulator's SIM_CLOCK (a simulated one, whatever its speed)",
    )
    p.add_argument("--build", default=None, help="build dir with the LCM types")
    p.add_argument(
        "--identity",
        default="SCM",
        help="the certificate that signs V2I and light commands: NAME.cert/.sk in "
        "$AUTODRIVE_KEY_DIR (tools/keys issue --name NAME --role scm; default SCM)",
    )
    p.add_argument(
        "--tls-cert",
        type=Path,
        help="serve HTTPS with this PEM certificate (with --tls-key); the session cookie is "
        "then Secure",
    )
    p.add_argument("--tls-key", type=Path, help="the PEM private key of --tls-cert")
    p.add_argument("--log-level", default="warning", help="uvicorn's log level")
    a = p.parse_args(argv)
    if not 0 < a.port < 65536:
        p.error(f"--port {a.port}: expected 1..65535")
    if a.history_hz < 0 or not 0 < a.advisory_hz <= 100:
        p.error("--history-hz must be >= 0 and --advisory-hz in (0, 100]")
    names = [v.strip() for v in a.vehicles.split(",") if v.strip()]
    for v in names:
        if not (v.isalnum() and v.isupper()):
            p.error(f"--vehicles: '{v}' is not a vehicle name (capitals and digits, e.g. NIGEL1)")
    if (a.tls_cert is None) != (a.tls_key is None):
        p.error("--tls-cert and --tls-key go together")
    for opt, path in (("--tls-cert", a.tls_cert), ("--tls-key", a.tls_key)):
        if path is not None and not path.is_file():
            p.error(f"{opt} {path}: no such file")
    a.vehicle_list = names
    return a


class _Server(uvicorn.Server):
    """uvicorn's server without its own signal handling (it re-raises SIGTERM after shutdown,
    so the process would die before the SCM's writer has committed its last rows)."""

    @contextlib.contextmanager
    def capture_signals(self) -> Iterator[None]:
        yield


def serve(argv: list[str]) -> int:
    from autodrive.scm.api import create_app
    from autodrive.scm.service import Scm

    a = parse_serve(argv)
    try:
        m = maps.load(a.map)
    except maps.MapDescriptionError as err:
        print(f"autodrive-scm: --map: {err}", file=sys.stderr)
        return 2
    try:
        engine = open_engine(a.db)
        migrate(engine)
    except DatabaseError as err:
        print(f"autodrive-scm: {err}", file=sys.stderr)
        return 2
    try:
        scm = Scm(
            m,
            engine,
            find_build(a.build),
            a.lcm_url,
            a.vehicle_list,
            a.history_hz,
            a.advisory_hz,
            a.clock,
            a.identity,
        )
    except CertificateError as err:
        print(f"autodrive-scm: --identity {a.identity}: {err}", file=sys.stderr)
        return 2
    tls = a.tls_cert is not None
    app = create_app(scm, tls=tls)
    config = uvicorn.Config(
        app,
        host=a.host,
        port=a.port,
        log_level=a.log_level,
        ws="websockets-sansio",
        ssl_certfile=str(a.tls_cert) if tls else None,
        ssl_keyfile=str(a.tls_key) if tls else None,
    )
    server = _Server(config)
    for sig in (signal.SIGINT, signal.SIGTERM):  # stop serving, then stop the SCM: exit 0
        signal.signal(sig, lambda _n, _f: setattr(server, "should_exit", True))
    scm.start()

    def announce() -> None:  # once uvicorn listens
        while not server.started and not server.should_exit:
            time.sleep(0.02)
        if server.started:
            print(f"SCM ready http{'s' if tls else ''}://{a.host}:{a.port}/", flush=True)

    threading.Thread(target=announce, daemon=True).start()
    try:
        server.run()
    finally:
        scm.stop()
    return 0


def user_command(argv: list[str]) -> int:
    p = argparse.ArgumentParser(prog="autodrive-scm user", description="Manage SCM users.")
    sub = p.add_subparsers(dest="action", required=True)
    add = sub.add_parser("add", help="add a user or reset one's role and password")
    add.add_argument("name")
    add.add_argument("--role", required=True, choices=["operator", "viewer"])
    add.add_argument("--db", default=default_url())
    add.add_argument(
        "--password-stdin",
        action="store_true",
        help="read the password from the first line of stdin (scripts)",
    )
    a = p.parse_args(argv)
    if a.password_stdin:
        password = sys.stdin.readline().rstrip("\n")
    else:
        password = getpass.getpass(f"password for {a.name}: ")
        if getpass.getpass("again: ") != password:
            print("autodrive-scm user add: the passwords differ", file=sys.stderr)
            return 2
    try:
        engine = open_engine(a.db)
        migrate(engine)
        new = add_user(sessions(engine), a.name, a.role, password)
    except (DatabaseError, UserError) as err:
        print(f"autodrive-scm user add: {err}", file=sys.stderr)
        return 2
    print(f"{'added' if new else 'updated'} user {a.name} ({a.role})")
    return 0


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if args and args[0] == "user":
        return user_command(args[1:])
    return serve(args)


if __name__ == "__main__":
    sys.exit(main())
