/* sim_jpeg: RGB -> JPEG in memory with libjpeg(-turbo), reusing its output buffer. */
#ifndef SIM_JPEG_H
#define SIM_JPEG_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sim_jpeg sim_jpeg_t;

/* quality 1..100. Returns NULL on a bad quality or no memory. Caller owns the result. */
sim_jpeg_t *sim_jpeg_create(int quality);
void sim_jpeg_destroy(sim_jpeg_t *j);

/* Encodes rgb (rows top-down, width*height*3 bytes). On success returns 0 and points *out at
 * the JPEG bytes (owned by j, valid until the next encode or destroy). */
int sim_jpeg_encode(sim_jpeg_t *j, const uint8_t *rgb, int width_px, int height_px,
                    const uint8_t **out, size_t *size_bytes);

#ifdef __cplusplus
}
#endif
#endif /* SIM_JPEG_H */
