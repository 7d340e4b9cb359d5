# Debian's Arduino AVR core (arduino-core-avr): the one place both the AVR firmware build and the
# host tests find it. NANO_BOOTLOADER_HEX is the classic Nano's bootloader (ATmegaBOOT, 57600
# baud, at 0x7800), which the upload test runs in simavr.
set(ARDUINO_AVR_DIR "/usr/share/arduino/hardware/arduino/avr" CACHE PATH "Arduino AVR core")
set(NANO_BOOTLOADER_HEX "${ARDUINO_AVR_DIR}/bootloaders/atmega/ATmegaBOOT_168_atmega328.hex")
