/* Scripted driver: stands in for the Jetson runtime in tests and benchmarks by sending real
 * protocol frames (COMMAND at 50 Hz, arming with engaged=0 then engaged=1 as the failsafe
 * requires) into the emulated Nano's UART.
 * Specs: "constant:throttle=<-1..1>,steering=<-1..1>[,start=<s>][,stop_after=<s>]"
 *        "route:<NAME>[,speed=<0..1>][,start=<s>][,stop_after=<s>][,lookahead=<m>][,laps=<n>]
 *               [,perturb=<0..1>][,lane_shift=<-3..3>]"
 *   start: first command time [s] (default 0); stop_after: the driver goes quiet at this sim
 *   time [s] (default never), which must trip the Nano's failsafe.
 *   route: the map's named route, driven by pure pursuit (route_driver.h) at throttle `speed`
 *   (fraction of top speed, default 0.8) with `lookahead` [m]; the simulator places the car at
 *   the route's start and sets throttle/steering before each frame. laps: laps of a loop route
 *   before the run ends (default 1). perturb: amplitude of seeded steering perturbations
 *   (normalised, default 0: none) the route driver adds now and then, so a recording holds the
 *   expert's recoveries (route_driver.h). lane_shift: drive the lane that many lane widths to
 *   the route's left (negative: right) in the route's direction (default 0: its own lane). */
#ifndef SIM_SCRIPT_H
#define SIM_SCRIPT_H

#include <stddef.h>
#include <stdint.h>

#include "protocol.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SCRIPT_PERIOD_US 20000u               /* 50 Hz, the runtime's command rate */
#define SCRIPT_ROUTE_SPEED_DEFAULT 0.8        /* route: throttle, fraction of top speed */
#define SCRIPT_ROUTE_LOOKAHEAD_DEFAULT_M 0.20 /* route: pure pursuit lookahead [m] */
#define SCRIPT_ROUTE_LANE_SHIFT_MAX 3         /* route: |lane_shift| [lanes] */

typedef struct script {
  double throttle, steering; /* normalised [-1, 1]; a route driver sets them before each poll */
  int route;                 /* 1: "route:" spec */
  char route_name[64];
  double lookahead_m;        /* route: pure pursuit lookahead [m] */
  int laps;                  /* route: laps of a loop before the run ends */
  double perturb;            /* route: steering perturbation amplitude, normalised (0: none) */
  int lane_shift;            /* route: lanes to the left of the route's own (negative: right) */
  int64_t start_us, stop_us; /* stop_us < 0: never */
  int64_t next_us;
  uint16_t cmd_seq;
  uint8_t frame_seq;
  int sent;
} script_t;

/* Parses spec. Returns 0, or -1 with a message naming the bad part in err. */
int script_parse(script_t *s, const char *spec, char *err, size_t err_sz);
/* Frames due at sim time now_us are encoded into out (cap >= 2 * PROTOCOL_MAX_FRAME).
 * Returns the number of bytes written. */
size_t script_poll(script_t *s, int64_t now_us, uint8_t *out, size_t cap);

#ifdef __cplusplus
}
#endif
#endif
