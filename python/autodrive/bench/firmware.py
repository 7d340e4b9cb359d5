"""tools/bench firmware: firmware figures, all on the real ELF in simavr (simulated time, so
they do not depend on how busy this machine is). Sizes from avr-size, then bin/nano-sil-bench
on nano_avr/nigel_nano.elf (see firmware/nano/simavr/README.md). tools/bench builds the release
preset (that builds the ELF too, in $AUTODRIVE_BUILD/nano_avr). Progress and the detailed
figures on stderr; the last stdout line is JSON."""

from __future__ import annotations

import subprocess

from autodrive.bench import Progress, build_dir, last_json, print_figures
from autodrive.core import seeds
from autodrive.bench.goals import at_least, at_most, judge

UNSEEDED = seeds.unseeded("the real ELF in simavr, simulated time: no random input")
# The firmware's goals (sizes on the ATmega328P with its bootloader; timings in simulated time)
GOALS = {
    "flash_fits": at_most("flash_bytes", 23040),
    "ram_fits": at_most("ram_static_bytes", 1200),
    "encoder_isr_cycles": at_most("encoder_isr_cycles_max", 150),
    "cmd_to_pwm": at_most("cmd_to_pwm_us", 2000),
    "failsafe_stop": at_most("failsafe_stop_ms", 150),
    "telemetry_rate": at_least("telemetry_hz", 100),
    "edge_rate": at_least("max_edge_rate_hz", 16640),
}

# ATmega328P with its 2 KiB bootloader: what the firmware may use.
FLASH_USABLE_BYTES = 30720
RAM_BYTES = 2048
FLASH_SECTIONS = (".text", ".data")  # the initialisers live in flash
RAM_SECTIONS = (".data", ".bss", ".noinit")
log = Progress("firmware")


def section_sizes(elf: str) -> dict[str, int]:
    """Section name -> size [bytes] from `avr-size -A`."""
    text = subprocess.run(["avr-size", "-A", elf], check=True, capture_output=True, text=True)
    sizes = {}
    for line in text.stdout.splitlines():
        words = line.split()
        if len(words) >= 2 and words[0].startswith(".") and words[1].isdigit():
            sizes[words[0]] = int(words[1])
    return sizes


def main(argv: list[str]) -> int:
    if argv:
        print(__doc__.strip())
        return 0 if argv[0] in ("-h", "--help") else 2
    build = build_dir("firmware")
    elf = build / "nano_avr" / "nigel_nano.elf"
    bench = build / "bin" / "nano-sil-bench"
    for f, what in ((elf, "firmware ELF"), (bench, "nano-sil-bench")):
        if not f.exists():
            log(f"ERROR: {what} {f} is missing (build the release preset)")
            return 1
    sizes = section_sizes(str(elf))
    flash = sum(sizes.get(s, 0) for s in FLASH_SECTIONS)
    ram = sum(sizes.get(s, 0) for s in RAM_SECTIONS)
    log(
        f"{elf}: flash {flash} bytes of {FLASH_USABLE_BYTES} usable, static RAM {ram} bytes of {RAM_BYTES}"
    )
    out = subprocess.run([str(bench), str(elf)], check=True, stdout=subprocess.PIPE, text=True)
    try:
        figures = last_json(out.stdout, "nano-sil-bench")
    except ValueError as e:
        log(f"ERROR: {e}")
        return 1
    print_figures(
        judge({"flash_bytes": flash, "ram_static_bytes": ram, **figures}, GOALS, UNSEEDED)
    )
    return 0
