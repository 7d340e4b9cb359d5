/* Wheel encoders: channel A on INT0 (left, D2) / INT1 (right, D3), any edge; channel B
 * (D4 / D5) is read inside the ISR and decoded by core/encoder (x2: one count per A edge, + when
 * A != B after the edge, i.e. A leads B). 1920 counts per wheel revolution. */
#ifndef AUTODRIVE_HAL_AVR_ENCODER_H
#define AUTODRIVE_HAL_AVR_ENCODER_H
#include <stdint.h>

/* 1: that side's encoder is mounted mirrored (set to match the car's wiring). */
#ifndef HAL_AVR_ENCODER_LEFT_INVERT
#define HAL_AVR_ENCODER_LEFT_INVERT 0u
#endif
#ifndef HAL_AVR_ENCODER_RIGHT_INVERT
#define HAL_AVR_ENCODER_RIGHT_INVERT 0u
#endif
#ifdef __cplusplus
extern "C" {
#endif
void hal_avr_encoder_init(void);
/* Atomic snapshot of both counters [counts]. */
void hal_avr_encoder_read(int32_t *left_counts, int32_t *right_counts);
#ifdef __cplusplus
}
#endif
#endif
