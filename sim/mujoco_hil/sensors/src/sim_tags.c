/* sim_tags: see sim_tags.h. */
#include "sim_tags.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>
#include <png.h>

int sim_tags_count(void) {
  apriltag_family_t *fam = tag36h11_create();
  int n = (int)fam->ncodes;
  tag36h11_destroy(fam);
  return n;
}

int sim_tags_write_png(const char *path, int tag_id, int px_per_cell, char *err, size_t err_len) {
  if (!path || px_per_cell < 1 || px_per_cell > 256) {
    if (err && err_len) snprintf(err, err_len, "sim_tags: bad path or px_per_cell (1..256)");
    return -1;
  }
  apriltag_family_t *fam = tag36h11_create();
  if (tag_id < 0 || tag_id >= (int)fam->ncodes) {
    if (err && err_len)
      snprintf(err, err_len, "sim_tags: tag id %d is not in tag36h11 (0..%u)", tag_id,
               fam->ncodes - 1);
    tag36h11_destroy(fam);
    return -1;
  }
  /* libapriltag renders the tag itself: one pixel per cell, white outer border included */
  image_u8_t *cells = apriltag_to_image(fam, tag_id);
  tag36h11_destroy(fam);
  int side = cells->width * px_per_cell;
  FILE *f = fopen(path, "wb");
  if (!f) {
    if (err && err_len)
      snprintf(err, err_len, "sim_tags: cannot write '%s': %s", path, strerror(errno));
    image_u8_destroy(cells);
    return -1;
  }
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
  png_infop info = png ? png_create_info_struct(png) : NULL;
  uint8_t *row = malloc((size_t)side * 3);
  int rc = -1;
  if (png && info && row && setjmp(png_jmpbuf(png)) == 0) {
    png_init_io(png, f);
    png_set_IHDR(png, info, (png_uint_32)side, (png_uint_32)side, 8, PNG_COLOR_TYPE_RGB,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    for (int y = 0; y < side; y++) {
      const uint8_t *src = cells->buf + (y / px_per_cell) * cells->stride;
      for (int x = 0; x < side; x++) memset(row + 3 * x, src[x / px_per_cell], 3);
      png_write_row(png, row);
    }
    png_write_end(png, NULL);
    rc = 0;
  }
  png_destroy_write_struct(png ? &png : NULL, info ? &info : NULL);
  free(row);
  image_u8_destroy(cells);
  if (fclose(f) != 0) rc = -1;
  if (rc != 0 && err && err_len)
    snprintf(err, err_len, "sim_tags: PNG write failed for '%s'", path);
  return rc;
}

int sim_tags_mjcf(const char *prefix, const char *png_path, double tag_size_m, char *asset_out,
                  size_t asset_len, char *geom_out, size_t geom_len) {
  double half_m = 0.5 * tag_size_m * 10.0 / 8.0; /* plate = whole 10-cell image */
  double t_m = SIM_TAGS_PLATE_THICKNESS_M;
  int n = snprintf(asset_out, asset_len,
                   "<texture name=\"%stag_tex\" type=\"2d\" file=\"%s\"/>\n"
                   "<material name=\"%stag_mat\" texture=\"%stag_tex\" texrepeat=\"1 1\" "
                   "specular=\"0\" shininess=\"0\" reflectance=\"0\"/>\n",
                   prefix, png_path, prefix, prefix);
  if (n < 0 || (size_t)n >= asset_len) return -1;
  /* quat (not euler: it does not depend on the model's angle unit): see sim_tags.h; the
   * overhead test checks the resulting heading */
  n = snprintf(geom_out, geom_len,
               "<geom name=\"%stag\" type=\"box\" size=\"%.6f %.6f %.6f\" pos=\"%.6f %.6f %.6f\" "
               "quat=\"%s\" material=\"%stag_mat\" contype=\"0\" conaffinity=\"0\" "
               "group=\"1\" mass=\"0\"/>\n",
               prefix, half_m, half_m, 0.5 * t_m, SIM_TAGS_OFFSET_X_M, SIM_TAGS_OFFSET_Y_M,
               SIM_TAGS_OFFSET_Z_M - 0.5 * t_m, SIM_TAGS_PLATE_QUAT, prefix);
  if (n < 0 || (size_t)n >= geom_len) return -1;
  return 0;
}
