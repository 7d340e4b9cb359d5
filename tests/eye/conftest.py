"""The Eye suite's scenario options (ctest gives each test its own, tests/eye/CMakeLists.txt)."""

import pytest


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("autodrive eye")
    group.addoption("--frames", type=int, default=60, help="frames fed to the Eye")
    group.addoption("--fps", type=float, default=10.0, help="rate of the frames fed [Hz]")
    group.addoption("--duration-s", default="6", help="simulated run [s]")
