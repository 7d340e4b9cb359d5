/* --eye-sync: the overhead cameras' frames in lockstep with the Eye (docs/design/clocks.md).
 *
 * An Eye run with `autodrive-eye run --sim-latency-ms L` publishes a frame's poses when
 * SIM_CLOCK reaches the frame's capture time + L, then EYE_FRAME_DONE (its capture time and L).
 * With --eye-sync the sim, having rendered and published a frame captured at t, never steps
 * past t + L before that frame is done: at the step that reaches t + L it publishes SIM_CLOCK
 * (so the Eye releases the poses at exactly that sim time) and waits. So the poses reach the
 * bus at capture + L of sim time however long the Eye takes in wall time, and a run's events do
 * not depend on how busy the host is.
 *
 * Before its first frame the sim waits up to EYE_SYNC_FIRST_S of wall time (or the wait limit,
 * if longer) for an Eye to say it is ready (so the Eye sees every frame, and a run repeats); an
 * Eye silent for the wait limit (--eye-sync-wait-s, EYE_SYNC_LOST_S by default) of wall time
 * while the sim waits is given up until it answers again, as --lockstep-client does with the
 * runtime. These are hang guards: a run where one fired depended on wall time. So each give-up
 * is a line on stderr with EYE_SYNC_GIVE_UP_MARK (the missions count them in the sim's log:
 * autodrive.hil.pose_source), and the exit line and --bench give the count. */
#ifndef SIM_APP_EYE_SYNC_H
#define SIM_APP_EYE_SYNC_H

#include <stdint.h>

#include <lcm/lcm.h>

#define EYE_SYNC_FIRST_S 60.0 /* [s] wall, at most, for an Eye before the first frame */
/* [s] wall: an Eye this long without finishing a frame waited for is given up. Longer than the
 * runtime's CLIENT_SYNC_LOST_S: four 1280x960 frames took over 2 s at a load of 45 on 2 cores
 * (Tiny Town, 2026-12-02), and an Eye given up for a slow frame makes the run depend on load. */
#define EYE_SYNC_LOST_S 10.0
#define EYE_SYNC_WAIT_MIN_S 0.1    /* [s] wall: the shortest --eye-sync-wait-s */
#define EYE_SYNC_WAIT_MAX_S 3600.0 /* [s] wall: the longest --eye-sync-wait-s */
/* Every give-up's stderr line has this (autodrive.hil.pose_source.EYE_SYNC_GIVE_UP_MARK). */
#define EYE_SYNC_GIVE_UP_MARK "--eye-sync gave up on the Eye"
#define EYE_SYNC_MAX_PENDING 64 /* frames sent and not yet done (an Eye far behind drops more) */

typedef struct eye_sync eye_sync_t;

/* Subscribes to EYE_FRAME_DONE on lcm (borrowed); wait_s [s wall]: how long a silent Eye is
 * waited for (EYE_SYNC_WAIT_MIN_S..EYE_SYNC_WAIT_MAX_S). NULL with a message in err on failure. */
eye_sync_t *eye_sync_create(lcm_t *lcm, double wait_s, char *err, size_t err_sz);
void eye_sync_destroy(eye_sync_t *e);
/* Before the first frame goes out: waits (EYE_SYNC_FIRST_S of wall time, or the wait limit if
 * longer, at most; a give-up if it runs out) for an Eye to say it is ready (EYE_FRAME_DONE,
 * utime -1), so that it has every frame from the first. */
void eye_sync_before_frame(eye_sync_t *e);
/* A frame captured at capture_us went out to the Eye (all overhead cameras of that time). */
void eye_sync_frame_sent(eye_sync_t *e, int64_t capture_us);
/* Reads the EYE_FRAME_DONE messages waiting (no wait). */
void eye_sync_poll(eye_sync_t *e);
/* 1 if the sim must not step past now_us before the Eye is done with a frame. */
int eye_sync_due(const eye_sync_t *e, int64_t now_us);
/* Waits until the Eye is done with every frame due by now_us, or gives it up. */
void eye_sync_wait(eye_sync_t *e, int64_t now_us);
/* Frames waited for, the wall time waited [s] and the give-ups, for the exit line. */
long eye_sync_stats(const eye_sync_t *e, double *waited_s, long *given_up);

#endif
