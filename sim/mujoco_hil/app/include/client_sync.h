/* Lockstep with the client on each car's Nano pty (autodrive-sim --lockstep-client and
 * --lockstep-frames): the stepping thread waits here for the runtime's bytes or frames. */
#ifndef SIM_APP_CLIENT_SYNC_H
#define SIM_APP_CLIENT_SYNC_H

#include <stdint.h>

#include "sim.h"

/* --lockstep-client: the sim never runs more than CLIENT_SYNC_HORIZON_US of sim time past the
 * last bytes a client wrote on a car's Nano pty. The runtime's bridge writes a COMMAND frame
 * every 20 ms of its clock, which is SIM_CLOCK: so the sim goes as fast as the runtime keeps
 * up, and the emulated Nano never sees a gap the runtime did not make (its failsafe is 100 ms). */
#define CLIENT_SYNC_HORIZON_US 40000
/* [s] wall without bytes: the client is gone; stop waiting for it */
#define CLIENT_SYNC_LOST_S 2.0
typedef struct {
  int started;                          /* a client has written at least once */
  int64_t lost_rx_us[SIM_MAX_CARS + 1]; /* host_rx of a client given up on (0: none) */
  uint32_t frames[SIM_MAX_CARS + 1];    /* --lockstep-frames: the client's frames so far */
} client_sync_t;

/* --lockstep-client: waits while a car's client is CLIENT_SYNC_HORIZON_US of sim time behind. */
void client_sync_wait_bytes(sim_t *s, client_sync_t *st);
/* --lockstep-frames: waits for one more whole frame from every car's client. */
void client_sync_wait_frame(sim_t *s, client_sync_t *st);
#define CLIENT_SYNC_FRAME_TICK_US 20000 /* [us] of sim time between the frames waited for */

#endif
