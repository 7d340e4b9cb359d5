"""Fixtures every Python test suite shares: the repository, the ctest build tree and its
programs, and an LCM bus of the test's own (ctest runs suites in parallel; each test gets a
port of its own so that two runs never hear each other).

ctest passes --build-dir (tests/CMakeLists.txt, autodrive_add_pytest) and, where the test
talks LCM, --lcm-port; by hand: `.venv/bin/python -m pytest tests/maps/test_api.py
--build-dir build/release`."""

from __future__ import annotations

import os
import socket
from pathlib import Path
from typing import Callable

import pytest
from pyhelpers import REPO_ROOT

LCM_GROUP = "239.255.76.67"


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("autodrive")
    group.addoption(
        "--build-dir",
        default=os.environ.get("AUTODRIVE_BUILD_DIR", str(REPO_ROOT / "build" / "release")),
        help="the CMake build tree whose programs the tests run (default: build/release)",
    )
    group.addoption(
        "--lcm-port",
        type=int,
        default=0,
        help="UDP port of the test's LCM multicast bus (default: a free one)",
    )
    group.addoption(
        "--program",
        action="append",
        default=[],
        metavar="NAME=PATH",
        help="where program NAME is (default: <build-dir>/bin/NAME); repeatable",
    )


@pytest.fixture(scope="session")
def root() -> Path:
    """The repository's root."""
    return REPO_ROOT


@pytest.fixture(scope="session")
def build_dir(pytestconfig: pytest.Config) -> Path:
    """The ctest build tree (CMAKE_BINARY_DIR)."""
    return Path(pytestconfig.getoption("build_dir")).resolve()


@pytest.fixture(scope="session")
def bin_dir(build_dir: Path) -> Path:
    """Where the build puts its programs (CMAKE_RUNTIME_OUTPUT_DIRECTORY)."""
    return build_dir / "bin"


@pytest.fixture(scope="session")
def program(pytestconfig: pytest.Config, bin_dir: Path) -> Callable[[str], str]:
    """program(NAME): the path of a built program (--program NAME=PATH, else bin_dir/NAME)."""
    given = dict(p.split("=", 1) for p in pytestconfig.getoption("program"))

    def path(name: str) -> str:
        return given.get(name, str(bin_dir / name))

    return path


def free_udp_port() -> int:
    """A UDP port no socket on this host is bound to now."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("", 0))
        return int(s.getsockname()[1])


@pytest.fixture(scope="session")
def lcm_port(pytestconfig: pytest.Config) -> int:
    """The port of this test's LCM bus: ctest's --lcm-port (its range is planned per test in
    the suites' CMakeLists), else a free one."""
    return int(pytestconfig.getoption("lcm_port")) or free_udp_port()


@pytest.fixture(scope="session")
def lcm_url(lcm_port: int) -> str:
    """The test's LCM bus: UDP multicast on loopback (ttl=0), on lcm_port."""
    return f"udpm://{LCM_GROUP}:{lcm_port}?ttl=0"
