#!/usr/bin/env bash
# tools/flash without a board: --help, the avrdude and PlatformIO commands it would run
# (--dry-run), and clear errors for bad options or a missing image. usage: test_flash.sh <root>
set -euo pipefail
flash="$1/tools/flash"
fail() { echo "FAIL: $*" >&2; exit 1; }
"$flash" --help | grep -q -- "--new-bootloader" || fail "--help"
out="$("$flash" --dry-run --port /dev/ttyFAKE0 --hex /tmp/x.hex)"
echo "$out" | grep -q "avrdude -p atmega328p -c arduino -P /dev/ttyFAKE0 -b 57600 -D -U flash:w:/tmp/x.hex:i" || fail "old bootloader: $out"
out="$("$flash" --dry-run --new-bootloader --port /dev/ttyFAKE0 --hex /tmp/x.hex)"
echo "$out" | grep -q -- "-b 115200" || fail "new bootloader: $out"
out="$("$flash" --dry-run --pio --new-bootloader --port /dev/ttyFAKE0)"
echo "$out" | grep -q "pio run -d .* -e nanoatmega328new -t upload --upload-port /dev/ttyFAKE0" || fail "pio: $out"
if "$flash" --bogus 2>/dev/null; then fail "unknown option accepted"; fi
err="$("$flash" --hex /nonexistent.hex --port /dev/null 2>&1 || true)"
echo "$err" | grep -q "'/nonexistent.hex' does not exist" || fail "missing image: $err"
err="$("$flash" --hex "$0" --port /dev/ttyNOPE9 2>&1 || true)"
echo "$err" | grep -q "serial port '/dev/ttyNOPE9' does not exist" || fail "missing port: $err"
echo "tools/flash ok"
