/* Lockstep with the client on each car's Nano pty (client_sync.h). */
#include "client_sync.h"

#include <stdio.h>
#include <time.h>

#include <autodrive_channels.h>

#include "app_common.h"

void client_sync_wait_bytes(sim_t *s, client_sync_t *st) {
  const int64_t now_us = sim_time_us(s);
  for (int c = 1; c <= sim_cars(s); c++) {
    const int64_t rx_us = sim_host_rx_us(s, c);
    if (rx_us < 0) continue; /* no client yet on this car */
    st->started = 1;
    if (st->lost_rx_us[c] == rx_us + 1 || now_us - rx_us < CLIENT_SYNC_HORIZON_US) continue;
    const double t_give_up = app_wall_s() + CLIENT_SYNC_LOST_S;
    while (!app_stop_requested() && !sim_nano_wait_input(s, c, 50)) {
      if (app_wall_s() > t_give_up) {
        fprintf(stderr,
                "[autodrive-sim] " AUTODRIVE_VEHICLE_PREFIX
                "%d: no bytes from the client for %.1f s (wall): "
                "running on without it\n",
                c, CLIENT_SYNC_LOST_S);
        st->lost_rx_us[c] = rx_us + 1;
        break;
      }
      struct timespec ts = {0, 1000000}; /* a hung-up pty polls ready at once: 1 ms pause */
      nanosleep(&ts, NULL);
    }
  }
}

/* --lockstep-frames: at every CLIENT_SYNC_FRAME_TICK_US of sim time (0 included) the sim waits
 * until the client on each car's Nano pty has written one more whole frame, and hands it to the
 * emulated Nano at that step. A runtime whose bridge sends one frame per SIM_CLOCK tick
 * (bridge.sync_to_sim_clock) then reaches the firmware at the same sim steps in every run, so
 * a HIL run with a seed gives the same ground truth twice. A client silent for CLIENT_SYNC_LOST_S
 * of wall time (CLIENT_SYNC_FRAME_FIRST_S before its first frame) is given up, as --lockstep-client
 * does. */
#define CLIENT_SYNC_FRAME_FIRST_S 60.0
void client_sync_wait_frame(sim_t *s, client_sync_t *st) {
  for (int c = 1; c <= sim_cars(s); c++) {
    if (st->lost_rx_us[c] != 0) continue;
    const uint32_t before = st->frames[c];
    const double t_give_up =
        app_wall_s() + (before ? CLIENT_SYNC_LOST_S : CLIENT_SYNC_FRAME_FIRST_S);
    while (!app_stop_requested() && (st->frames[c] = sim_host_frames(s, c)) == before) {
      if (app_wall_s() > t_give_up) {
        fprintf(stderr,
                "[autodrive-sim] " AUTODRIVE_VEHICLE_PREFIX
                "%d: no frame from the client for %.1f s (wall): "
                "running on without it\n",
                c, before ? CLIENT_SYNC_LOST_S : CLIENT_SYNC_FRAME_FIRST_S);
        st->lost_rx_us[c] = 1;
        break;
      }
      if (!sim_nano_wait_input(s, c, 50)) {
        struct timespec ts = {0, 1000000}; /* a hung-up pty polls ready at once: 1 ms pause */
        nanosleep(&ts, NULL);
      }
    }
    st->started = 1;
  }
}
