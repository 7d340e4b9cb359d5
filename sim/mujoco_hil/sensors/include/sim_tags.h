/* sim_tags: real tag36h11 AprilTag textures for the car roofs, from libapriltag's own codes.
 *
 * Geometry (the convention the Eye must use):
 * - A tag36h11 image is 10 x 10 cells: a 1-cell white outer border, a 1-cell black border, a
 *   6 x 6 data grid. The AprilTag "tag size" is the edge of the black square = 8 cells.
 *   The roof box top face carries the whole 10-cell image, so the box is 10/8 * tag_size_m
 *   wide and long. Default tag_size_m = SIM_TAGS_SIZE_M.
 * - The plate's centre sits at the roof tag offset from base_link (SIM_TAGS_OFFSET_*), top
 *   face at that height.
 * - Orientation: seen from above, the tag's image "up" (its top row as printed by
 *   apriltag_to_image) points along the car's +x (forward), its image "right" along the car's
 *   -y (the car's right). So for a camera looking straight down with image up = world +y,
 *   a car with yaw psi shows the tag rotated by psi - 90 deg. libapriltag returns corners
 *   p[0..3] = bottom-left, bottom-right, top-right, top-left of the printed tag, so the car's
 *   heading is the direction from the mean of (p[0], p[1]) to the mean of (p[3], p[2]).
 * - libapriltag corners are +0.5 px off OpenCV's pixel-centre convention (eye/README.md).
 */
#ifndef SIM_TAGS_H
#define SIM_TAGS_H

#include <stddef.h>

#include <autodrive_vehicle.h>

#ifdef __cplusplus
extern "C" {
#endif

/* from vehicle/nigel.params: tag_size_m (black-square edge) and tag_pos_m (plate centre from
 * base_link, top face at its z) [m] */
#define SIM_TAGS_SIZE_M AUTODRIVE_VEHICLE_TAG_SIZE_M
#define SIM_TAGS_OFFSET_X_M AUTODRIVE_VEHICLE_TAG_POS_M_X
#define SIM_TAGS_OFFSET_Y_M AUTODRIVE_VEHICLE_TAG_POS_M_Y
#define SIM_TAGS_OFFSET_Z_M AUTODRIVE_VEHICLE_TAG_POS_M_Z
#define SIM_TAGS_PLATE_THICKNESS_M 0.002
/* MuJoCo maps a 2D texture onto a box's top face with the image's up along the box's +y;
 * the plate is yawed -90 deg in its body (quat below) so the tag's up is the car's +x. */
#define SIM_TAGS_PLATE_QUAT "0.70710678 0 0 -0.70710678"

/* Number of ids in tag36h11 (587). */
int sim_tags_count(void);

/* Writes tag36h11 tag tag_id as an 8-bit RGB PNG at path, px_per_cell pixels per cell
 * (>= 1; 10 * px_per_cell pixels square; use >= 8 so texture filtering keeps edges sharp).
 * Returns 0, or -1 with a message naming the path or id in err. */
int sim_tags_write_png(const char *path, int tag_id, int px_per_cell, char *err, size_t err_len);

/* MJCF text for one car's roof tag, written into buf (buf_len bytes, NUL-terminated):
 * asset_out gets <texture name="<prefix>tag_tex" type="2d" file="png_path"/> and
 *   <material name="<prefix>tag_mat" texture="<prefix>tag_tex"/>;
 * geom_out gets the roof plate <geom> to put inside the car's base_link body
 *   (name "<prefix>tag", contype/conaffinity 0, group 1, box sized for tag_size_m, with the
 *   orientation above). Returns 0, or -1 if a buffer is too small. */
int sim_tags_mjcf(const char *prefix, const char *png_path, double tag_size_m, char *asset_out,
                  size_t asset_len, char *geom_out, size_t geom_len);

#ifdef __cplusplus
}
#endif
#endif /* SIM_TAGS_H */
