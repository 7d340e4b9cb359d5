/* Manual driving from the window (autodrive-sim --view, the Car section's Driving radio set to
 * Manual): the held drive keys are piped into an autodrive-teleop process, which signs its
 * commands as a person (AUTHORITY_PERSON, the car's key) and publishes <VEH>_COMMAND; the
 * runtime's bridge takes them like any other source (signature, replay window, control lease).
 * The simulator neither signs nor commands: it types, as a terminal would. Back to Autonomous
 * closes the pipe: teleop sends a last disengaged command and quits, the person's lease lapses
 * (bridge.command_lease_ms) and the autonomy's next engaged command takes it back.
 * With --gamepad PATH (a Linux joystick, /dev/input/jsN) teleop also reads the pad (--joystick:
 * hold the dead-man button, sticks for throttle and steering) beside the keys. A pad unplugged
 * while driving: teleop stops the car and prints "gamepad lost" on its stdout, a pipe read here
 * (the HUD says so; the keys go on working).
 * Why a pipe and not a channel: key state on LCM would be unsigned input that a signer turns
 * into a person's commands (anyone on the bus could drive); a pipe reaches only the child, and
 * the one signer (autodrive::auth::Signer in autodrive-teleop) stays where it is. */
#ifndef SIM_APP_MANUAL_DRIVE_H
#define SIM_APP_MANUAL_DRIVE_H

#include <stddef.h>
#include <sys/types.h>

/* [s] wall between repeats of the held keys on the pipe (a terminal's autorepeat ~30 ms) */
#define MANUAL_DRIVE_REPEAT_S 0.05
/* [ms] teleop's dead-man: a key not repeated for this long counts as released. Long enough
 * for a frame of software GL on a busy machine (the keys are read once a frame). */
#define MANUAL_DRIVE_HOLD_MS 1000

typedef struct manual_drive {
  pid_t pid;           /* autodrive-teleop, 0 when none */
  int fd;              /* its standard input (write end), -1 when none */
  int out;             /* its standard output (read end, non-blocking), -1 when none */
  const char *gamepad; /* --gamepad: the joystick device teleop reads, or NULL */
  int gamepad_lost;    /* teleop said the pad is gone (until manual driving starts again) */
  char line[64];       /* teleop's stdout line being read */
  int line_n;
  int car;             /* the car it drives (1-based) */
  int keys;            /* SIM_VIEWER_KEY_* written last */
  double next_write_s; /* [s] wall: the next repeat */
  int failed;          /* teleop could not start or exited on its own: off until asked again */
  char status[160];    /* for the HUD: who drives, or why manual driving stopped */
} manual_drive_t;

/* gamepad: --gamepad's path, or NULL (the caller checked it at start-up). */
void manual_drive_init(manual_drive_t *m, const char *gamepad);
/* Called every loop pass while the window is open: starts teleop for car when manual turns on
 * (or the ego car changes), writes the held keys (on a change at once, else every
 * MANUAL_DRIVE_REPEAT_S), stops it when manual turns off. url: the sim's LCM URL. Returns 1
 * while teleop runs, 0 when off, -1 when it could not start or died (message in status and on
 * stderr; the caller sets the radio back to Autonomous). */
int manual_drive_update(manual_drive_t *m, int manual, int car, int keys, const char *url,
                        double now_s);
/* Closes the pipe and waits for teleop to quit (its last command is a disengaged stop). */
void manual_drive_stop(manual_drive_t *m);

#endif
