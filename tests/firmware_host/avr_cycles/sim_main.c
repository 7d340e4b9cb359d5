/* Host side: runs core_cycles.elf in simavr until it sets core_done, then prints the timing
 * results (read from the AVR's RAM at the addresses given on the command line). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <simavr/sim_avr.h>
#include <simavr/sim_elf.h>

int main(int argc, char **argv) {
  elf_firmware_t fw;
  avr_t *avr;
  unsigned long res_addr, done_addr;
  unsigned long long guard = 0;
  static const char *names[] = {
      "init",           "step_idle",         "step_imu_read", "step_battery",
      "step_telemetry", "rx_command_frame",  "enc_edge_call", "step_idle_max",
      "schema_hash",    "step_ahrs_gravity", "step_ahrs_mag", "step_ahrs_integrate"};
  unsigned i;
  if (argc != 4) {
    fprintf(stderr, "usage: %s <core_cycles.elf> <core_results addr> <core_done addr>\n", argv[0]);
    return 2;
  }
  memset(&fw, 0, sizeof fw);
  if (elf_read_firmware(argv[1], &fw) != 0) {
    fprintf(stderr, "%s: cannot read ELF\n", argv[1]);
    return 1;
  }
  res_addr = strtoul(argv[2], NULL, 16) & 0xFFFFu;
  done_addr = strtoul(argv[3], NULL, 16) & 0xFFFFu;
  avr = avr_make_mcu_by_name("atmega328p");
  if (!avr) return 1;
  avr_init(avr);
  avr->frequency = 16000000;
  avr_load_firmware(avr, &fw);
  while (avr->data[done_addr] == 0) {
    int st = avr_run(avr);
    if (st == cpu_Done || st == cpu_Crashed) {
      fprintf(stderr, "AVR stopped early (state %d)\n", st);
      return 1;
    }
    if (++guard > 400000000ull) {
      fprintf(stderr, "timeout\n");
      return 1;
    }
  }
  printf("{");
  for (i = 0; i < sizeof names / sizeof names[0]; ++i) {
    const uint8_t *p = &avr->data[res_addr + 4u * i];
    unsigned long v = (unsigned long)p[0] | ((unsigned long)p[1] << 8) |
                      ((unsigned long)p[2] << 16) | ((unsigned long)p[3] << 24);
    printf("%s\"%s_cycles\": %lu", i ? ", " : "", names[i], v);
  }
  printf("}\n");
  return 0;
}
