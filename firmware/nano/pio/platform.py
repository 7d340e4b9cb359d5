# PlatformIO platform class of the offline Nigel AVR platform. Everything it needs comes from
# Debian (gcc-avr, avr-libc, arduino-core-avr, avrdude), so it declares no packages to fetch.
from platformio.public import PlatformBase


class NigelavrPlatform(PlatformBase):
    pass
