#!/usr/bin/env bash
# Builds the firmware core for the ATmega328P (avr-gcc -Os, gc-sections, as the firmware does)
# with a stub HAL, runs it in simavr and prints the core's own cost per entry point [cycles
# at 16 MHz] and its flash/RAM footprint. Usage: tests/firmware_host/avr_cycles/run.sh [outdir]
# With AVR_CORE_MAX_PASS_CYCLES=<n> set, exits 1 if any single nano_core_step pass costs more
# (ctest firmware.core_avr_cycles uses 16000 = 1 ms at 16 MHz: the loop must keep 1 kHz).
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(cd "$HERE/../../.." && pwd)"
CORE="$ROOT/firmware/nano/core"
OUT="${1:-$ROOT/build/avr-core-cycles}"
case "${1:-}" in -h|--help) sed -n 2,4p "$0"; exit 0;; esac
mkdir -p "$OUT"
INC=(-I"$CORE/nano_core" -I"$CORE/protocol" -I"$CORE/failsafe" -I"$CORE/actuation" -I"$CORE/lights" -I"$CORE/battery"
     -I"$CORE/wheel_speed" -I"$CORE/ahrs" -I"$CORE/encoder")
SRC=("$CORE/protocol/protocol.c" "$CORE/nano_core/nano_core.c" "$CORE/failsafe/failsafe.c" "$CORE/actuation/actuation.c"
     "$CORE/lights/lights.c" "$CORE/battery/battery.c" "$CORE/wheel_speed/wheel_speed.c" "$CORE/ahrs/ahrs.c")
avr-gcc -mmcu=atmega328p -DF_CPU=16000000UL -Os -std=gnu99 -Wall -Wextra -Werror \
  -ffunction-sections -fdata-sections -Wl,--gc-sections "${INC[@]}" \
  "$HERE/core_cycles.c" "${SRC[@]}" -lm -o "$OUT/core_cycles.elf"
# The core alone (no timing harness): what it adds to a firmware image.
printf 'int main(void){return 0;}\n' > "$OUT/empty.c"
avr-gcc -mmcu=atmega328p -Os "$OUT/empty.c" -o "$OUT/empty.elf"
gcc -O2 -Wall -Wextra -Werror "$HERE/sim_main.c" -o "$OUT/sim_core_cycles" \
  $(pkg-config --cflags --libs simavr) -lelf
addr() { avr-nm "$OUT/core_cycles.elf" | awk -v s="$1" '$3==s {print $1}'; }
size_line() { avr-size -A "$1" | awk '/^\.text|^\.data|^\.bss/ {s[$1]=$2} END {print s[".text"]+s[".data"], s[".data"]+s[".bss"]}'; }
read -r flash ram < <(size_line "$OUT/core_cycles.elf")
read -r flash0 ram0 < <(size_line "$OUT/empty.elf")
echo "[avr-core] harness ELF: flash $flash B, static RAM $ram B (an empty program: $flash0 B, $ram0 B)" >&2
core_size_hex="$(avr-nm -S "$OUT/core_cycles.elf" | awk '$4=="core" {print $2}')"
echo "[avr-core] sizeof(nano_core_t): $((16#$core_size_hex)) B" >&2
json="$(XDG_CACHE_HOME="$OUT/.cache" "$OUT/sim_core_cycles" "$OUT/core_cycles.elf" "$(addr core_results)" "$(addr core_done)" 2>/dev/null)"
echo "$json"
if [ -n "${AVR_CORE_MAX_PASS_CYCLES:-}" ]; then
  worst="$(echo "$json" | tr ',{}' '\n\n\n' | awk -F': ' '/"step_/ {if ($2 > m) {m = $2; k = $1}} END {print m, k}')"
  echo "[avr-core] most expensive loop pass: ${worst#* } ${worst%% *} cycles (limit $AVR_CORE_MAX_PASS_CYCLES)" >&2
  [ "${worst%% *}" -le "$AVR_CORE_MAX_PASS_CYCLES" ] || { echo "[avr-core] FAIL: a loop pass exceeds the limit" >&2; exit 1; }
fi
