/* sim_video: an MP4 (H.264, yuv420p) video writer fed RGB frames, one per fixed period of sim
 * time, so that frame k of the file is sim time t0 + k / fps: its clock is the sim's, at any
 * real-time factor. It pipes raw frames into Debian's ffmpeg (a child process, no shell); a
 * missing ffmpeg is a clear error at open. The simulator's --video/--record, the Record button
 * and the learning API's ad_video_* (Gym episodes) all write through it.
 *
 * sim_video_stamp burns a sim time into a frame (top-left, white on black, a built-in 3x5
 * digit font), so that a still taken from the video tells its sim time. */
#ifndef SIM_VIDEO_H
#define SIM_VIDEO_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sim_video sim_video_t;

/* Starts writing path (overwritten) at width_px x height_px (even, >= 16) and fps frames per
 * second of sim time. ffmpeg: $AUTODRIVE_FFMPEG, else "ffmpeg" on PATH. Returns NULL with a
 * message naming path and the cause in err. */
sim_video_t *sim_video_open(const char *path, int width_px, int height_px, double fps, char *err,
                            size_t err_sz);
/* Appends one frame: rgb rows top-down, width*height*3 bytes. Returns 0, or -1 (ffmpeg died:
 * message in err). */
int sim_video_frame(sim_video_t *v, const uint8_t *rgb, char *err, size_t err_sz);
/* Frames written so far. */
long sim_video_frames(const sim_video_t *v);
/* Finishes the file and waits for ffmpeg. Returns 0, or -1 with ffmpeg's exit status in err.
 * NULL is fine (returns 0). */
int sim_video_close(sim_video_t *v, char *err, size_t err_sz);

/* Draws "t_s" as e.g. "12.345 S" into rgb (width_px x height_px, rows top-down) at the top-left
 * corner, scale_px pixels per font pixel (>= 1). */
void sim_video_stamp(uint8_t *rgb, int width_px, int height_px, double t_s, int scale_px);

#ifdef __cplusplus
}
#endif
#endif /* SIM_VIDEO_H */
