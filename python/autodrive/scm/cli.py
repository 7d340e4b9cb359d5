"""autodrive-scm: the Smart City Manager server, and its user administration.

    autodrive-scm --map tiny_town [--db URL] [--host H] [--port N] [--lcm-url URL]
                  [--instance N] [--vehicles NIGEL1,NIGEL2,NIGEL3] [--history-hz HZ]
                  [--clock wall|sim] [--build DIR]
    autodrive-scm user add NAME --role operator|viewer [--db URL] [--password-stdin] [--reset]

Prints "SCM ready http://HOST:PORT/" on stdout once it serves."""

from __future__ import annotations

import argparse
import contextlib
import errno
import getpass
import signal
import socket
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import uvicorn
from sqlalchemy import Engine

from autodrive.core import channels
from autodrive.core.v2x_cert import CertificateError
from autodrive import maps
from autodrive.core.settings import Instance, InstanceError, instance, use_instance
from autodrive.scm.core.config import (
    DEFAULT_HOST,
    DEFAULT_MAP,
    default_url,
    find_build,
)
from autodrive.scm.core.db import DatabaseError, migrate, open_engine, sessions
from autodrive.scm.core.security import UserError, add_user
from autodrive.scm.crud import user_exists


class DefaultsHelp(argparse.ArgumentDefaultsHelpFormatter):
    """--help with each option's default, unless the option's own text says it."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        text = action.help or ""
        if action.default is None or "default" in text or isinstance(action.default, bool):
            return text
        return super()._get_help_string(action)


def parse_serve(argv: list[str]) -> argparse.Namespace:
    p = argparse.ArgumentParser(
        prog="autodrive-scm",
        description="Smart City Manager: vehicles, traffic lights, signs and an event log in a "
        "database; light control; V2I advisories on LCM; a REST/WebSocket API (/docs) and a web "
        "app. Users: 'autodrive-scm user add NAME --role operator'.",
        formatter_class=DefaultsHelp,
    )
    rule = channels.load().instances
    p.add_argument("--map", default=DEFAULT_MAP, help="map name or description YAML")
    p.add_argument("--db", default=default_url(), help="sqlite:///PATH or postgresql://...")
    p.add_argument("--host", default=DEFAULT_HOST, help="address to serve on")
    p.add_argument(
        "--port",
        type=int,
        default=None,
        help=f"web port (default: the instance's, {rule.web_port} + {rule.port_step} N)",
    )
    p.add_argument(
        "--lcm-url",
        default=channels.load().url_default,
        help="LCM bus; one on the default port moves to the instance's (default: %(default)s)",
    )
    p.add_argument(
        "--instance",
        type=int,
        default=None,
        help="this session's instance N (default: $AUTODRIVE_INSTANCE, else 0): its own LCM "
        "port and web port, so two users' SCMs and simulators on one machine never meet",
    )
    p.add_argument(
        "--vehicles",
        default="",
        help="cars to advise, e.g. NIGEL1,NIGEL2,NIGEL3 (default: empty, every car whose pose is "
        "seen)",
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
        help="the SCM's clock (the lights' yellow, all-red, programs and actuated holds, the "
        "advisories' rate, the poses' freshness): this machine's (a real town), or the "
        "simulator's SIM_CLOCK (a simulated one, whatever its speed; a SIM_CLOCK still for 5 s "
        "of wall time makes every car stale)",
    )
    p.add_argument(
        "--build", default=None, help="build dir with the LCM types (default: the first built)"
    )
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
    try:
        if a.instance is not None:
            use_instance(a.instance)  # for this process and the programs it starts
        a.session = instance()
    except InstanceError as err:
        p.error(str(err))
    a.port = a.session.web_port(a.port)
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


def bind_web_port(host: str, port: int, session: Instance) -> socket.socket | str:
    """The listening socket of host:port, or the message that says why not and what to do."""
    sock = socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind((host, port))
    except OSError as err:
        sock.close()
        if err.errno == errno.EADDRINUSE:
            return (
                f"web port {port} on {host} is already in use (another SCM, perhaps another "
                f"user's session): pick another with --port P, or {session.describe()}"
            )
        return f"cannot serve on {host}:{port}: {err.strerror}"
    sock.listen(128)
    return sock


def serve(argv: list[str]) -> int:
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
        return _serve_on(a, m, engine)
    finally:
        engine.dispose()  # close the pool's connections before the interpreter exits


def _serve_on(a: argparse.Namespace, m: maps.MapDescription, engine: Engine) -> int:
    from autodrive.scm.api import create_app
    from autodrive.scm.service import Scm

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
    sock = bind_web_port(a.host, a.port, a.session)
    if isinstance(sock, str):
        print(f"autodrive-scm: {sock}", file=sys.stderr)
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
        server.run(sockets=[sock])
    finally:
        scm.stop()
        sock.close()
    return 0


def user_command(argv: list[str]) -> int:
    p = argparse.ArgumentParser(prog="autodrive-scm user", description="Manage SCM users.")
    sub = p.add_subparsers(dest="action", required=True)
    add = sub.add_parser(
        "add",
        help="add a user (--reset: set an existing one's role and password)",
        formatter_class=DefaultsHelp,
    )
    add.add_argument("name")
    add.add_argument("--role", required=True, choices=["operator", "viewer"])
    add.add_argument("--db", default=default_url(), help="the SCM's database")
    add.add_argument(
        "--reset",
        action="store_true",
        help="replace the role and password of a user who exists (without it: refused)",
    )
    add.add_argument(
        "--password-stdin",
        action="store_true",
        help="read the password from the first line of stdin (scripts)",
    )
    a = p.parse_args(argv)
    try:
        engine = open_engine(a.db)
    except DatabaseError as err:
        print(f"autodrive-scm user add: {err}", file=sys.stderr)
        return 2
    try:
        return _user_add(a, engine)
    finally:
        engine.dispose()  # close the pool's connections before the interpreter exits


def _user_add(a: argparse.Namespace, engine: Engine) -> int:
    try:
        migrate(engine)
        with sessions(engine)() as s:
            exists = user_exists(s, a.name)
    except DatabaseError as err:
        print(f"autodrive-scm user add: {err}", file=sys.stderr)
        return 2
    if exists and not a.reset:
        print(
            f"autodrive-scm user add: user {a.name} exists already; --reset replaces its role "
            "and password",
            file=sys.stderr,
        )
        return 2
    if a.password_stdin:
        password = sys.stdin.readline().rstrip("\n")
    else:
        password = getpass.getpass(f"password for {a.name}: ")
        if getpass.getpass("again: ") != password:
            print("autodrive-scm user add: the passwords differ", file=sys.stderr)
            return 2
    try:
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
