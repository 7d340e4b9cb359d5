/* The emulated Nano's host side (sim_internal.h): the client on the Nano pty, whose bytes are
 * moved onto the Nano's UART wire and back in batches of the host I/O period, and the
 * in-process scripted driver that writes protocol frames instead of a client. */
#include <math.h>
#include <poll.h>

#include "sim_internal.h"

/* Is the host link (ptys) serviced in the step that ends at s->time_us + SIM_STEP_US? */
int sim_host_io_due(const sim_t *s) {
  return (s->time_us / SIM_STEP_US + 1) % s->host_io_period_steps == 0;
}

static void sim_count_host_frame(const protocol_frame_t *f, void *ctx) {
  (void)f;
  ((sim_car_t *)ctx)->host_frames++;
}

/* Moves what the client wrote on the pty onto the Nano's RX wire, now; counts its frames. */
void sim_read_host(sim_t *s, sim_car_t *c) {
  uint8_t buf[512];
  const size_t room = uart_space(&c->rx) < sizeof buf ? uart_space(&c->rx) : sizeof buf;
  const size_t n = ptylink_read(&c->pty, buf, room);
  if (n == 0) return;
  uart_push(&c->rx, buf, n);
  c->host_rx_us = s->time_us;
  protocol_parser_feed(&c->host_parser, buf, n, sim_count_host_frame, c);
}

/* Unread bytes [bytes] on the pty above which nobody is reading it (free lockstep only): 40 ms
 * of the Nano's telemetry. Writing on into the kernel's queue costs tens of microseconds per
 * write (the tty layer hands each write to a kernel worker), more than the car's whole 1 ms
 * step; a client that reads keeps the queue near empty. */
#define SIM_PTY_UNREAD_IDLE_BYTES 256
static int sim_host_io_due_car(const sim_t *s, const sim_car_t *c, int io_due) {
  if (!io_due || !c->host_idle) return io_due;
  return (s->time_us / SIM_STEP_US + 1) % SIM_HOST_IDLE_PERIOD_MS == 0;
}

/* The step's first half of the pty: what the client wrote reaches the Nano's RX wire. */
void sim_host_receive(sim_t *s, sim_car_t *c, int io_due_all, sim_host_turn_t *turn) {
  turn->io_due = c->has_pty && sim_host_io_due_car(s, c, io_due_all);
  turn->frames_before = c->host_frames;
  turn->rx_before_us = c->host_rx_us;
  if (c->has_pty && turn->io_due) sim_read_host(s, c);
}

/* The in-process scripted driver (script.h) writes its frames onto the RX wire; a route
 * driver first updates its command by pure pursuit before each frame. */
void sim_script_feed(sim_t *s, sim_car_t *c) {
  if (!c->has_script) return;
  if (s->route && s->time_us >= c->script.next_us) {
    const mjtNum *q = s->d->qpos + c->root_qpos;
    const double yaw =
        atan2(2.0 * (q[3] * q[6] + q[4] * q[5]), 1.0 - 2.0 * (q[5] * q[5] + q[6] * q[6]));
    route_driver_update(s->route, q[0], q[1], yaw, &c->script.throttle, &c->script.steering);
  }
  uint8_t buf[512];
  const size_t n = script_poll(&c->script, s->time_us, buf, sizeof buf);
  uart_push(&c->rx, buf, n);
}

/* The step's second half: the Nano's bytes that crossed the TX wire go to the pty, batched
 * over the host I/O period (or drained when there is no pty). */
void sim_host_send(sim_t *s, sim_car_t *c, const sim_host_turn_t *turn) {
  if (!c->has_pty) {
    uint8_t buf[512];
    uart_pop(&c->tx, SIM_STEP_US, buf, sizeof buf); /* nobody listens: the wire just drains */
    return;
  }
  const size_t room = sizeof c->tx_pending - c->tx_pending_n;
  c->tx_pending_n += uart_pop(&c->tx, SIM_STEP_US, c->tx_pending + c->tx_pending_n, room);
  const int full = c->tx_pending_n == sizeof c->tx_pending;
  if (full && !turn->io_due && c->host_idle) {
    c->tx_pending_n = 0; /* idle: dropped here, as the full pty would drop them */
  } else if (turn->io_due || full) {
    const int read_any =
        c->host_rx_us != turn->rx_before_us || c->host_frames != turn->frames_before;
    const int may_idle = s->host_io_period_steps > 1 && !read_any;
    if (may_idle && ptylink_unread(&c->pty) >= SIM_PTY_UNREAD_IDLE_BYTES) {
      c->host_idle = 1; /* nobody reads: one ioctl instead of a write into a queue */
    } else {
      /* a full pty drops bytes */
      const size_t sent = ptylink_write(&c->pty, c->tx_pending, c->tx_pending_n);
      c->host_idle = may_idle && c->tx_pending_n > 0 && sent == 0;
    }
    c->tx_pending_n = 0;
  }
}

const char *sim_nano_link(const sim_t *s, int car) {
  return s->car[car - 1].has_pty ? s->car[car - 1].pty.link_path : "";
}
int64_t sim_host_rx_us(const sim_t *s, int car) {
  const sim_car_t *c = &s->car[car - 1];
  return c->has_pty ? c->host_rx_us : -1;
}

uint32_t sim_host_frames(sim_t *s, int car) {
  sim_car_t *c = &s->car[car - 1];
  if (!c->has_pty) return 0;
  sim_read_host(s, c);
  return c->host_frames;
}

int sim_nano_wait_input(const sim_t *s, int car, int timeout_ms) {
  const sim_car_t *c = &s->car[car - 1];
  if (!c->has_pty) return 0;
  struct pollfd p = {c->pty.master_fd, POLLIN, 0};
  return poll(&p, 1, timeout_ms) > 0 && (p.revents & POLLIN);
}
