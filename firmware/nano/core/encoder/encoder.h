/* Quadrature decoder for the wheel encoders, called from the AVR pin interrupts.
 *
 * Which edges count: BOTH edges (rising and falling) of channel A; channel B only gives the
 * direction (its level is sampled at the A edge). That is x2 decoding: with the car's encoder
 * (8 A-cycles per motor revolution, 120:1 gearbox) one wheel revolution is 1920 counts
 * (ENCODER_COUNTS_PER_REV). On the Nano, A is on INT0/INT1 (D2 left, D3 right) set to CHANGE,
 * B on D4 / D5 (read inside the ISR, no interrupt needed).
 *
 * Direction: forward (+1) when A leads B, i.e. when the A level just after the edge differs
 * from the B level. A wheel mounted mirrored (the left one, usually) is set with invert = 1
 * so that + is forward on both sides.
 *
 * Portable C99, header-only so the ISR inlines it (a handful of instructions on AVR). */
#ifndef AUTODRIVE_ENCODER_H
#define AUTODRIVE_ENCODER_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define ENCODER_COUNTS_PER_REV 1920L /* [counts] per wheel revolution */

typedef struct encoder {
  volatile int32_t counts; /* [counts], + forward; on AVR read it with interrupts off */
  uint8_t invert;          /* 1: this side's channels are mirrored */
} encoder_t;

static inline void encoder_init(encoder_t *e, uint8_t invert) {
  e->counts = 0;
  e->invert = (uint8_t)(invert ? 1u : 0u);
}

/* One edge (either direction) on channel A. a, b: the pin levels (0 or nonzero) read right
 * after the edge. */
/* Forced inline: under -Os a call would double the ISR's cycles (77 -> ~150). */
static inline __attribute__((always_inline)) void encoder_edge_a(encoder_t *e, uint8_t a,
                                                                 uint8_t b) {
  uint8_t fwd = (uint8_t)(((a ? 1u : 0u) ^ (b ? 1u : 0u) ^ e->invert) & 1u);
  if (fwd)
    e->counts = e->counts + 1;
  else
    e->counts = e->counts - 1;
}

#ifdef __cplusplus
}
#endif
#endif
