#!/usr/bin/env bash
# tools/flash without a board: --help, the PlatformIO command it would run (--dry-run) for
# each bootloader and platform, and clear errors for bad options or a missing port.
# usage: test_flash.sh <root>
set -euo pipefail
flash="$1/tools/flash"
fail() { echo "FAIL: $*" >&2; exit 1; }
"$flash" --help | grep -q -- "--new-bootloader" || fail "--help"
out="$("$flash" --dry-run --port /dev/ttyFAKE0)"
echo "$out" | grep -q "pio run -d .* -e nano_offline -t upload --upload-port /dev/ttyFAKE0" || fail "default: $out"
out="$("$flash" --dry-run --new-bootloader --port /dev/ttyFAKE0)"
echo "$out" | grep -q -- "-e nano_offline_new -t upload" || fail "new bootloader: $out"
out="$("$flash" --dry-run --online --new-bootloader --port /dev/ttyFAKE0)"
echo "$out" | grep -q -- "-e nanoatmega328new -t upload --upload-port /dev/ttyFAKE0" || fail "online: $out"
out="$("$flash" --dry-run --online --port /dev/ttyFAKE0)"
echo "$out" | grep -q -- "-e nanoatmega328 -t upload" || fail "online old: $out"
if "$flash" --bogus 2>/dev/null; then fail "unknown option accepted"; fi
if "$flash" --hex x.hex 2>/dev/null; then fail "--hex (gone: PlatformIO builds the image) accepted"; fi
err="$("$flash" --port /dev/ttyNOPE9 2>&1 || true)"
echo "$err" | grep -q "serial port '/dev/ttyNOPE9' does not exist" || fail "missing port: $err"
echo "tools/flash ok"
