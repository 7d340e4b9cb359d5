/* sim_jpeg: see sim_jpeg.h. libjpeg errors longjmp back here instead of exit()ing. */
#include "sim_jpeg.h"

#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>

#include <jpeglib.h>

struct sim_jpeg_err {
  struct jpeg_error_mgr mgr;
  jmp_buf jump;
};

struct sim_jpeg {
  struct jpeg_compress_struct cinfo;
  struct sim_jpeg_err jerr;
  int quality;
  unsigned char *buf; /* jpeg_mem_dest output, reused across frames */
  unsigned long cap;  /* its usable size [bytes] */
};

static void jpeg_error_exit(j_common_ptr c) {
  struct sim_jpeg_err *e = (struct sim_jpeg_err *)c->err;
  longjmp(e->jump, 1);
}

sim_jpeg_t *sim_jpeg_create(int quality) {
  if (quality < 1 || quality > 100) return NULL;
  sim_jpeg_t *volatile j = calloc(1, sizeof *j); /* volatile: read after a longjmp */
  if (!j) return NULL;
  j->quality = quality;
  j->cinfo.err = jpeg_std_error(&j->jerr.mgr);
  j->jerr.mgr.error_exit = jpeg_error_exit;
  if (setjmp(j->jerr.jump)) {
    free(j);
    return NULL;
  }
  jpeg_create_compress(&j->cinfo);
  return j;
}

void sim_jpeg_destroy(sim_jpeg_t *j) {
  if (!j) return;
  jpeg_destroy_compress(&j->cinfo);
  free(j->buf);
  free(j);
}

int sim_jpeg_encode(sim_jpeg_t *j, const uint8_t *rgb, int width_px, int height_px,
                    const uint8_t **out, size_t *size_bytes) {
  if (!rgb || width_px < 1 || height_px < 1 || width_px > 65500 || height_px > 65500) return -1;
  struct jpeg_compress_struct *c = &j->cinfo;
  if (setjmp(j->jerr.jump)) {
    jpeg_abort_compress(c);
    return -1;
  }
  /* one buffer for a whole raw frame: libjpeg never needs to grow it in practice; if it does,
   * it mallocs a bigger one (ours stays ours to free) */
  unsigned long need = (unsigned long)width_px * (unsigned long)height_px * 3 + 65536;
  if (j->cap < need) {
    free(j->buf);
    j->buf = malloc(need);
    j->cap = j->buf ? need : 0;
    if (!j->buf) return -1;
  }
  unsigned char *mine = j->buf;
  unsigned long size = j->cap;
  jpeg_mem_dest(c, &j->buf, &size);
  c->image_width = (JDIMENSION)width_px;
  c->image_height = (JDIMENSION)height_px;
  c->input_components = 3;
  c->in_color_space = JCS_RGB;
  jpeg_set_defaults(c);
  jpeg_set_quality(c, j->quality, TRUE);
  c->dct_method = JDCT_IFAST;
  jpeg_start_compress(c, TRUE);
  while (c->next_scanline < c->image_height) {
    JSAMPROW row = (JSAMPROW)(rgb + (size_t)c->next_scanline * (size_t)width_px * 3);
    jpeg_write_scanlines(c, &row, 1);
  }
  jpeg_finish_compress(c);
  if (j->buf != mine) { /* libjpeg grew it: keep the new one, its size is at least size */
    free(mine);
    j->cap = size;
  }
  *out = j->buf;
  *size_bytes = size;
  return 0;
}
