"""The firmware-in-the-loop suite's inputs from the CMake build (tests/firmware_sil/
CMakeLists.txt): the Nano ELF, the bootloader image and the PlatformIO work dir."""

import pytest


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("autodrive firmware_sil")
    group.addoption("--nano-elf", help="the CMake AVR build's nigel_nano.elf")
    group.addoption("--bootloader-hex", help="the Nano bootloader image (ATmegaBOOT .hex)")
    group.addoption("--pio-work-dir", help="PlatformIO's private core and build dir (emptied)")


@pytest.fixture(scope="session")
def nano_elf(pytestconfig: pytest.Config) -> str:
    elf = pytestconfig.getoption("nano_elf")
    assert elf, "--nano-elf not given"
    return str(elf)
