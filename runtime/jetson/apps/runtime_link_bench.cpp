// runtime-link-bench: the measuring side of `tools/bench link` (the script starts the
// programs under test; this measures). Modes, each printing one JSON line on stdout:
//   serial    : a fake Nano on a pty (--pty); LCM command published -> its COMMAND frame
//               readable on the pty master [us] (cmd_to_serial_us_*)
//   pwm       : with nano-simavr --pwm-log; LCM command -> motor PWM register changed, from
//               the log's monotonic stamps [ms] (cmd_to_pwm_ms_*)
//   telemetry : <VEH>_STATE on LCM: its rate in the sender's clock (nano_time_us:
//               telemetry_hz) and on the host's (telemetry_hz_wall), inter-arrival jitter
//   ekf       : drives a loop through <VEH>_COMMAND, publishes Eye poses made from the sim's
//               ground truth (noise + latency), compares <VEH>_POSE_MAP and <VEH>_ODOM with
//               ground truth (ekf_*_rms)
//   flood     : a fake Nano on a pty (--pty) while --flood-hz commands a second go to
//               <VEH>_COMMAND (1 in 8 signed by the lease holder, the rest unsigned); COMMAND
//               frames per second on the serial link (serial_cmd_hz_under_flood), and with
//               --cpu-pid the CPU that process spent per wall second meanwhile
//               (flood_cpu_percent: 100 = one core)
// Commands are signed with the car's key (--key-file, default as autodrive-teleop's).
#include <autodrive/angles.hpp>
#include <autodrive/command_auth.hpp>
#include <autodrive_channels.h>
#include <CLI/CLI.hpp>
#include <lcm/lcm-cpp.hpp>

#include <autodrive/ground_truth_t.hpp>
#include <autodrive/odometry_t.hpp>
#include <autodrive/pose2d_t.hpp>
#include <autodrive/vehicle_command_t.hpp>
#include <autodrive/vehicle_state_t.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <atomic>
#include <deque>
#include <optional>
#include <fstream>
#include <random>
#include <sstream>
#include <iterator>
#include <thread>
#include <unistd.h>

#include <autodrive/core/clock.hpp>
#include <autodrive/v2x.hpp>
#include <autodrive_lcm/subscribe.hpp>
#include <autodrive/devtools/fake_nano.hpp>

namespace {

std::string fmt_number(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f", v);
  return b;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const double idx = p / 100.0 * (v.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(idx));
  const auto hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (v[hi] - v[lo]) * (idx - lo);
}

void progress(const char *fmt, double a, double b = 0) {
  std::fprintf(stderr, fmt, a, b);
  std::fflush(stderr);
}

std::optional<autodrive::auth::Signer> g_signer;  // set in main

autodrive::vehicle_command_t make_cmd(int32_t seq, float throttle, float steering, bool engaged) {
  autodrive::vehicle_command_t c{};
  c.utime = autodrive::clock::wall_us();
  c.seq = seq;
  c.throttle = throttle;
  c.steering = steering;
  c.engaged = engaged;
  if (g_signer) g_signer->sign(c);
  return c;
}

// A fake Nano on the pty that keeps the link up once the bridge said hello (100 Hz telemetry).
struct LinkedNano {
  autodrive::devtools::FakeNano nano;
  protocol_state_t st{};
  int64_t next_state_us = 0;
  explicit LinkedNano(const std::string &pty) : nano(pty) {
    nano.open();
    st.quat_q14[0] = PROTOCOL_QUAT_ONE;
  }
  void service() {
    nano.pump(1);
    const int64_t now = autodrive::clock::monotonic_us();
    if (nano.hellos_sent > 0 && now >= next_state_us) {
      st.nano_time_us += 10000;
      nano.send_state(st);
      next_state_us = now + 10000;
    }
  }
  // Serves until the bridge has sent 5 commands (linked), 30 s at most; false, said on stderr
  // for mode, when it never did.
  bool wait_linked(const char *mode, const std::string &pty) {
    const int64_t give_up = autodrive::clock::monotonic_us() + 30000000;
    while (nano.commands.size() < 5 && autodrive::clock::monotonic_us() < give_up) service();
    if (nano.commands.size() >= 5) return true;
    std::fprintf(stderr, "%s: the bridge never linked on %s\n", mode, pty.c_str());
    return false;
  }
};

// ---- flood ---------------------------------------------------------------------------
// User + system CPU time of a process [s], from /proc/<pid>/stat; NAN when unreadable.
double process_cpu_s(int pid) {
  std::ifstream f("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  const auto close = text.rfind(')');  // the command name may hold spaces
  if (close == std::string::npos) return NAN;
  std::istringstream rest(text.substr(close + 2));
  std::string field;
  double utime = NAN, stime = NAN;
  for (int i = 3; i <= 15 && rest >> field; ++i) {  // fields 14, 15: utime, stime [ticks]
    if (i == 14) utime = std::stod(field);
    if (i == 15) stime = std::stod(field);
  }
  return (utime + stime) / static_cast<double>(sysconf(_SC_CLK_TCK));
}

int run_flood(const std::string &url, const std::string &vehicle, const std::string &pty,
              double seconds, double flood_hz, int cpu_pid) {
  LinkedNano link(pty);
  auto &nano = link.nano;
  auto service = [&] { link.service(); };
  if (!link.wait_linked("flood", pty)) return 1;
  std::atomic<bool> done{false};
  std::atomic<long> sent{0};
  std::thread flooder([&] {
    lcm::LCM lcm(url);
    const std::string ch = vehicle + AUTODRIVE_CH_COMMAND_SUFFIX;
    const int64_t t0 = autodrive::clock::monotonic_us();
    int32_t seq = 0;
    while (!done) {
      // Catch up to the target count at each wake-up (1 ms): bursts, as a flooder sends.
      const auto due = static_cast<long>((autodrive::clock::monotonic_us() - t0) * 1e-6 * flood_hz);
      autodrive::vehicle_command_t junk = make_cmd(0, 1.0f, 1.0f, true);
      std::fill(junk.mac, junk.mac + autodrive::auth::kMacBytes, 0);  // unsigned
      while (sent < due && !done) {
        // One valid command of the lease holder in eight (each would once have become a frame),
        // the rest unsigned junk: the publisher's own signing then does not cap the rate.
        if (seq % 8 == 0) {
          const autodrive::vehicle_command_t c = make_cmd(seq, 0.2f, 0.0f, true);
          lcm.publish(ch, &c);
        } else {
          lcm.publish(ch, &junk);
        }
        ++seq;
        ++sent;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  });
  // Measure after a settling second.
  const int64_t t_settle = autodrive::clock::monotonic_us() + 1000000;
  while (autodrive::clock::monotonic_us() < t_settle) service();
  const std::size_t n0 = nano.commands.size();
  const long s0 = sent;
  const double cpu0 = cpu_pid > 0 ? process_cpu_s(cpu_pid) : NAN;
  const int64_t t0 = autodrive::clock::monotonic_us();
  int64_t next_print = t0 + 1000000;
  while (autodrive::clock::monotonic_us() < t0 + static_cast<int64_t>(seconds * 1e6)) {
    service();
    if (autodrive::clock::monotonic_us() >= next_print) {
      progress("flood: %.0f s, %.0f COMMAND frames so far\n",
               (autodrive::clock::monotonic_us() - t0) * 1e-6,
               static_cast<double>(nano.commands.size() - n0));
      next_print += 1000000;
    }
  }
  const double dt = (autodrive::clock::monotonic_us() - t0) * 1e-6;
  const double frames_hz = static_cast<double>(nano.commands.size() - n0) / dt;
  const double lcm_hz = static_cast<double>(sent - s0) / dt;
  const double cpu_percent = cpu_pid > 0 ? (process_cpu_s(cpu_pid) - cpu0) / dt * 100.0 : NAN;
  done = true;
  flooder.join();
  std::printf(
      "{\"serial_cmd_hz_under_flood\": %.2f, \"lcm_flood_msgs_per_s\": %.0f, "
      "\"flood_cpu_percent\": %s}\n",
      frames_hz, lcm_hz, std::isnan(cpu_percent) ? "null" : fmt_number(cpu_percent).c_str());
  return 0;
}

// ---- serial --------------------------------------------------------------------------
int run_serial(const std::string &url, const std::string &vehicle, const std::string &pty,
               int samples) {
  lcm::LCM lcm(url);
  LinkedNano link(pty);
  auto &nano = link.nano;
  auto service = [&] { link.service(); };
  if (!link.wait_linked("serial", pty)) return 1;
  std::vector<double> lat_us;
  std::mt19937 rng(3);
  int32_t seq = 0;
  for (int k = 0; k < samples; ++k) {
    // Spread the publish times over the heartbeat period.
    const int64_t pause_end =
        autodrive::clock::monotonic_us() + 30000 + static_cast<int64_t>(rng() % 20000);
    while (autodrive::clock::monotonic_us() < pause_end) service();
    const int16_t milli = static_cast<int16_t>(100 + (k % 2) * 400 + k % 7);
    const std::size_t mark = nano.commands.size();
    const auto c = make_cmd(seq++, milli / 1000.0f, 0.0f, true);
    const int64_t t0 = autodrive::clock::monotonic_us();
    lcm.publish(vehicle + AUTODRIVE_CH_COMMAND_SUFFIX, &c);
    bool seen = false;
    while (!seen && autodrive::clock::monotonic_us() < t0 + 1000000) {
      nano.pump(1);
      for (std::size_t i = mark; i < nano.commands.size(); ++i)
        if (nano.commands[i].throttle_milli == milli) seen = true;
    }
    if (seen) lat_us.push_back(static_cast<double>(autodrive::clock::monotonic_us() - t0));
    if (k % 100 == 0)
      progress("serial: %.0f samples, p50 so far %.0f us\n", k, percentile(lat_us, 50));
  }
  std::printf(
      "{\"cmd_to_serial_us_p50\": %.1f, \"cmd_to_serial_us_p90\": %.1f, "
      "\"cmd_to_serial_us_p99\": %.1f, \"cmd_to_serial_samples\": %zu}\n",
      percentile(lat_us, 50), percentile(lat_us, 90), percentile(lat_us, 99), lat_us.size());
  return lat_us.empty() ? 1 : 0;
}

// ---- pwm -----------------------------------------------------------------------------
struct PwmLine {
  int64_t t_sim_us;
  int64_t t_mono_us;
  int servo_us, duty;
};

std::vector<PwmLine> read_pwm_log(const std::string &path) {
  std::vector<PwmLine> out;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream f(line);
    double t_sim, t_mono, servo, duty;
    if (f >> t_sim >> t_mono >> servo >> duty)
      out.push_back({static_cast<int64_t>(t_sim), static_cast<int64_t>(t_mono),
                     static_cast<int>(servo), static_cast<int>(duty)});
  }
  return out;
}

struct StateWatch {
  std::vector<autodrive::vehicle_state_t> states;
  std::vector<int64_t> rx_mono_us;
  void on(const autodrive::vehicle_state_t *m) {
    states.push_back(*m);
    rx_mono_us.push_back(autodrive::clock::monotonic_us());
  }
  // Subscribes to the vehicle's STATE and waits (up to 60 s) for the first 10 messages.
  // Returns whether they came.
  bool attach(lcm::LCM &lcm, const std::string &vehicle) {
    autodrive_lcm::subscribe<autodrive::vehicle_state_t, StateWatch, &StateWatch::on>(
        lcm, vehicle + AUTODRIVE_CH_STATE_SUFFIX, this);
    const int64_t give_up = autodrive::clock::monotonic_us() + 60000000;
    while (states.size() < 10 && autodrive::clock::monotonic_us() < give_up) lcm.handleTimeout(20);
    return states.size() >= 10;
  }
};

int run_pwm(const std::string &url, const std::string &vehicle, const std::string &log_path,
            int samples, double command_hz) {
  const auto period_us = static_cast<int64_t>(std::llround(1e6 / command_hz));
  lcm::LCM lcm(url);
  StateWatch w;
  if (!w.attach(lcm, vehicle)) {
    std::fprintf(stderr, "pwm: no %s_STATE (bridge not linked to nano-simavr?)\n", vehicle.c_str());
    return 1;
  }
  int32_t seq = 0;
  // Engage at a base throttle and let the PWM settle, then alternate throttle steps; each
  // step's first motor register change after its publish time is one sample. Between steps
  // the command stream a controller sends: one command per period, drift-free. (It used to
  // publish after every LCM message received, at the STATE rate and above, faster than the
  // bridge's token bucket (command_rate_hz): the bucket stayed empty and each step waited for
  // a token, up to 10 ms, so the bench measured its own flood.)
  float throttle = 0.2f;
  int64_t next_cmd_us = autodrive::clock::monotonic_us();
  auto hold = [&](int64_t until_us) {
    for (int64_t now = autodrive::clock::monotonic_us(); now < until_us;
         now = autodrive::clock::monotonic_us()) {
      if (now >= next_cmd_us) {
        const auto c = make_cmd(seq++, throttle, 0.0f, true);
        lcm.publish(vehicle + AUTODRIVE_CH_COMMAND_SUFFIX, &c);
        next_cmd_us += period_us;
        if (next_cmd_us <= now) next_cmd_us = now + period_us;  // resync after a stall
      }
      const int64_t wait_us = std::min(next_cmd_us, until_us) - now;
      lcm.handleTimeout(static_cast<int>(std::max<int64_t>(1, (wait_us + 999) / 1000)));
    }
  };
  hold(autodrive::clock::monotonic_us() + 1500000);
  std::vector<int64_t> step_t0;
  for (int k = 0; k < samples; ++k) {
    throttle = (k % 2 == 0) ? 0.4f : 0.2f;
    const auto c = make_cmd(seq++, throttle, 0.0f, true);
    const int64_t t0 = autodrive::clock::monotonic_us();
    lcm.publish(vehicle + AUTODRIVE_CH_COMMAND_SUFFIX, &c);
    next_cmd_us = t0 + period_us;  // the step is this period's command
    step_t0.push_back(t0);
    hold(t0 + 700000 + static_cast<int64_t>((k * 7919) % 20000));
    if (k % 5 == 0) progress("pwm: %.0f steps\n", k);
  }
  throttle = 0.0f;
  const auto stop = make_cmd(seq++, 0.0f, 0.0f, false);
  lcm.publish(vehicle + AUTODRIVE_CH_COMMAND_SUFFIX, &stop);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const auto lines = read_pwm_log(log_path);
  std::vector<double> lat_ms;
  for (std::size_t k = 0; k < step_t0.size(); ++k) {
    const int64_t t0 = step_t0[k];
    const int64_t t_end = k + 1 < step_t0.size() ? step_t0[k + 1] : t0 + 700000;
    int prev_duty = -1;
    for (const auto &l : lines) {
      if (l.t_mono_us < t0) {
        prev_duty = l.duty;
        continue;
      }
      if (l.t_mono_us >= t_end) break;
      if (l.duty != prev_duty) {
        lat_ms.push_back((l.t_mono_us - t0) / 1000.0);
        break;
      }
    }
  }
  // simavr's speed over the measurement (simulated s per wall s): on a loaded machine it runs
  // slower than real time, which stretches every firmware-side delay in wall time.
  double rtf = NAN;
  const PwmLine *first = nullptr;
  for (const auto &l : lines)
    if (l.t_mono_us >= step_t0.front() && !first) first = &l;
  if (first && lines.back().t_mono_us > first->t_mono_us)
    rtf = double(lines.back().t_sim_us - first->t_sim_us) /
          double(lines.back().t_mono_us - first->t_mono_us);
  std::printf(
      "{\"cmd_to_pwm_ms_p50\": %.3f, \"cmd_to_pwm_ms_p90\": %.3f, \"cmd_to_pwm_samples\": %zu, "
      "\"simavr_real_time_factor\": %.3f, \"cmd_to_pwm_ms_p50_at_real_time\": %.3f, "
      "\"cmd_to_pwm_command_hz\": %.1f}\n",
      percentile(lat_ms, 50), percentile(lat_ms, 90), lat_ms.size(), rtf,
      percentile(lat_ms, 50) * rtf, command_hz);
  return lat_ms.empty() ? 1 : 0;
}

// ---- telemetry -----------------------------------------------------------------------
int run_telemetry(const std::string &url, const std::string &vehicle, double seconds,
                  const std::string &key_suffix) {
  lcm::LCM lcm(url);
  StateWatch w;
  w.attach(lcm, vehicle);  // the rate below counts whatever arrives after this
  w.states.clear();
  w.rx_mono_us.clear();
  const int64_t end = autodrive::clock::monotonic_us() + static_cast<int64_t>(seconds * 1e6);
  while (autodrive::clock::monotonic_us() < end) lcm.handleTimeout(20);
  if (w.rx_mono_us.size() < 3) {
    std::fprintf(stderr, "telemetry: too few %s_STATE messages\n", vehicle.c_str());
    return 1;
  }
  std::vector<double> dt_ms;
  int64_t nano_span_us = 0;  // the Nano's clock over the messages received (it wraps at 2^32)
  for (std::size_t i = 1; i < w.rx_mono_us.size(); ++i) {
    dt_ms.push_back((w.rx_mono_us[i] - w.rx_mono_us[i - 1]) / 1000.0);
    nano_span_us += static_cast<int64_t>(static_cast<uint32_t>(w.states[i].nano_time_us) -
                                         static_cast<uint32_t>(w.states[i - 1].nano_time_us));
  }
  const double n_intervals = static_cast<double>(w.rx_mono_us.size() - 1);
  // The rate in the sender's own time: what the firmware (or the simulator) sends and the
  // bridge forwards, whatever speed simavr keeps on a loaded host (a dropped STATE lowers it).
  // Rounded to 0.1 Hz: the 1.024 ms tick's jitter at the two ends is 1e-4 of a 10 s span.
  const double hz =
      nano_span_us > 0 ? std::round(n_intervals * 1e7 / double(nano_span_us)) / 10 : NAN;
  const double hz_wall = n_intervals * 1e6 / double(w.rx_mono_us.back() - w.rx_mono_us.front());
  const double med = percentile(dt_ms, 50);
  std::vector<double> dev;
  for (double d : dt_ms) dev.push_back(std::fabs(d - med));
  const char *k = key_suffix.c_str();
  std::printf(
      "{\"telemetry_hz%s\": %.1f, \"telemetry_hz_wall%s\": %.2f, \"telemetry_jitter_ms%s\": %.3f, "
      "\"telemetry_jitter_ms_p99%s\": %.3f, \"telemetry_period_ms_p50%s\": %.3f}\n",
      k, hz, k, hz_wall, k, percentile(dev, 50), k, percentile(dev, 99), k, med);
  return 0;
}

// ---- ekf -----------------------------------------------------------------------------
struct Pose {
  int64_t t_us;  // host wall clock [us]
  double x, y, yaw;
};

// Ground truth interpolated at t_us (host receive time); false outside the record.
bool truth_at(const std::vector<Pose> &gt, int64_t t_us, Pose *out) {
  auto it = std::lower_bound(gt.begin(), gt.end(), t_us,
                             [](const Pose &p, int64_t t) { return p.t_us < t; });
  if (it == gt.begin() || it == gt.end()) return false;
  const Pose &b = *it, &a = *(it - 1);
  const double f = double(t_us - a.t_us) / double(b.t_us - a.t_us);
  *out = {t_us, a.x + f * (b.x - a.x), a.y + f * (b.y - a.y),
          a.yaw + f * autodrive::angle_wrap_rad(b.yaw - a.yaw)};
  return true;
}

struct EkfBench {
  std::string vehicle;
  lcm::LCM *lcm = nullptr;
  std::optional<autodrive::v2x::Signer>
      eye_signer;  // the Eye's certificate: the EKF takes no other
  std::vector<Pose> gt, map, odom;
  std::deque<Pose> eye_queue;
  bool eye = true;
  double eye_period_us = 33333, eye_delay_us = 50000, noise_m = 0.005, noise_rad = 0.0087;
  int64_t next_eye_us = 0;
  std::mt19937 rng{11};
  bool collided = false;
  std::vector<std::pair<int64_t, int64_t>> clock_pairs;  // (wall receive, sim utime) [us]

  void on_gt(const autodrive::ground_truth_t *m) {
    const int64_t t = autodrive::clock::wall_us();
    clock_pairs.push_back({t, m->utime});
    gt.push_back({t, m->position_m[0], m->position_m[1], m->yaw_rad});
    collided = collided || m->in_collision;
    if (eye && t >= next_eye_us) {
      next_eye_us = t + static_cast<int64_t>(eye_period_us);
      std::normal_distribution<double> nm(0, noise_m), nr(0, noise_rad);
      eye_queue.push_back({t, m->position_m[0] + nm(rng), m->position_m[1] + nm(rng),
                           autodrive::angle_wrap_rad(m->yaw_rad + nr(rng))});
    }
  }
  void on_map(const autodrive::odometry_t *m) {
    map.push_back({m->utime, m->x_m, m->y_m, m->yaw_rad});
  }
  void on_odom(const autodrive::odometry_t *m) {
    odom.push_back({m->utime, m->x_m, m->y_m, m->yaw_rad});
  }
  // Eye poses leave `eye_delay_us` after capture, stamped with the capture time (like the Eye).
  void flush_eye() {
    const int64_t now = autodrive::clock::wall_us();
    while (!eye_queue.empty() && eye_queue.front().t_us + eye_delay_us <= now) {
      const Pose &p = eye_queue.front();
      autodrive::pose2d_t e{};
      e.utime = p.t_us;
      e.vehicle = vehicle;
      e.frame_id = "map";
      e.source = autodrive::pose2d_t::SOURCE_EYE;
      e.x_m = p.x;
      e.y_m = p.y;
      e.yaw_rad = p.yaw;
      e.covariance[0] = e.covariance[4] = noise_m * noise_m;
      e.covariance[8] = noise_rad * noise_rad;
      eye_signer->sign(vehicle + AUTODRIVE_CH_POSE_EYE_SUFFIX, e, p.t_us);
      lcm->publish(vehicle + AUTODRIVE_CH_POSE_EYE_SUFFIX, &e);
      eye_queue.pop_front();
    }
  }
};

// RMS position [m] and heading [deg] errors of `est` against ground truth in [t0, t1];
// `align` maps the estimate's frame onto the map frame first (odom frame).
void rms(const std::vector<Pose> &est, const std::vector<Pose> &gt, int64_t t0, int64_t t1,
         bool align, double *pos_m, double *yaw_deg, int *n) {
  double dx0 = 0, dy0 = 0, dth = 0, ox = 0, oy = 0;
  if (align) {
    // T = GT(t0) * EST(t0)^-1 from the first estimate in the window.
    for (const auto &e : est) {
      Pose g;
      if (e.t_us >= t0 && truth_at(gt, e.t_us, &g)) {
        dth = autodrive::angle_wrap_rad(g.yaw - e.yaw);
        ox = e.x;
        oy = e.y;
        dx0 = g.x;
        dy0 = g.y;
        break;
      }
    }
  }
  double se = 0, sy = 0;
  *n = 0;
  for (const auto &e : est) {
    if (e.t_us < t0 || e.t_us > t1) continue;
    Pose g;
    if (!truth_at(gt, e.t_us, &g)) continue;
    double x = e.x, y = e.y, yaw = e.yaw;
    if (align) {
      const double c = std::cos(dth), s = std::sin(dth);
      x = dx0 + c * (e.x - ox) - s * (e.y - oy);
      y = dy0 + s * (e.x - ox) + c * (e.y - oy);
      yaw = e.yaw + dth;
    }
    se += (x - g.x) * (x - g.x) + (y - g.y) * (y - g.y);
    const double dyaw = autodrive::angle_wrap_rad(yaw - g.yaw) * 180.0 / M_PI;
    sy += dyaw * dyaw;
    ++*n;
  }
  *pos_m = *n ? std::sqrt(se / *n) : NAN;
  *yaw_deg = *n ? std::sqrt(sy / *n) : NAN;
}

int run_ekf(const std::string &url, const std::string &vehicle, double seconds, double throttle,
            double steering, double eye_delay_ms) {
  lcm::LCM lcm(url);
  EkfBench b;
  b.vehicle = vehicle;
  b.lcm = &lcm;
  b.eye_delay_us = eye_delay_ms * 1000.0;
  b.eye_signer = autodrive::v2x::Signer::load("runtime-link-bench", "EYE");
  if (!b.eye_signer) return 2;
  autodrive_lcm::subscribe<autodrive::ground_truth_t, EkfBench, &EkfBench::on_gt>(
      lcm, vehicle + AUTODRIVE_CH_GROUND_TRUTH_SUFFIX, &b);
  autodrive_lcm::subscribe<autodrive::odometry_t, EkfBench, &EkfBench::on_map>(
      lcm, vehicle + AUTODRIVE_CH_POSE_MAP_SUFFIX, &b);
  autodrive_lcm::subscribe<autodrive::odometry_t, EkfBench, &EkfBench::on_odom>(
      lcm, vehicle + AUTODRIVE_CH_ODOM_SUFFIX, &b);
  const int64_t give_up = autodrive::clock::monotonic_us() + 60000000;
  while ((b.odom.size() < 20 || b.gt.size() < 20) && autodrive::clock::monotonic_us() < give_up) {
    lcm.handleTimeout(20);
    b.flush_eye();
  }
  if (b.odom.size() < 20 || b.gt.size() < 20) {
    std::fprintf(stderr, "ekf: no %s_ODOM or ground truth (runtime/sim not running?)\n",
                 vehicle.c_str());
    return 1;
  }
  // Let the Eye place the map estimate, then drive the loop.
  const int64_t settle = autodrive::clock::monotonic_us() + 1000000;
  while (autodrive::clock::monotonic_us() < settle) {
    lcm.handleTimeout(10);
    b.flush_eye();
  }
  // The loop lasts `seconds` of the simulator's time (its ground truth's stamps), so a loaded
  // machine that slows the simulator does not shorten the drive; the wall limit is a hang guard.
  const int64_t t0 = autodrive::clock::wall_us();
  const int64_t sim0 = b.clock_pairs.back().second;
  const int64_t loop_us = static_cast<int64_t>(seconds * 1e6);
  const int64_t hang_guard =
      autodrive::clock::monotonic_us() + std::max<int64_t>(600000000, 40 * loop_us);
  const auto sim_driven_us = [&] { return b.clock_pairs.back().second - sim0; };
  int32_t seq = 0;
  int64_t next_cmd = 0, next_progress = autodrive::clock::monotonic_us() + 10000000;
  while (sim_driven_us() < loop_us) {
    const int64_t now = autodrive::clock::monotonic_us();
    if (now > hang_guard) {
      std::fprintf(stderr, "ekf: the simulator advanced only %.1f s of %.1f s (hang guard)\n",
                   sim_driven_us() * 1e-6, seconds);
      return 1;
    }
    if (now >= next_cmd) {
      const auto c =
          make_cmd(seq++, static_cast<float>(throttle), static_cast<float>(steering), true);
      lcm.publish(vehicle + AUTODRIVE_CH_COMMAND_SUFFIX, &c);
      next_cmd = now + 20000;
    }
    if (now >= next_progress) {
      progress("ekf: %.0f s of sim time driven, %.0f map estimates\n", sim_driven_us() * 1e-6,
               static_cast<double>(b.map.size()));
      next_progress = now + 10000000;
    }
    lcm.handleTimeout(5);
    b.flush_eye();
  }
  const int64_t t1 = autodrive::clock::wall_us();
  const auto stop = make_cmd(seq++, 0.0f, 0.0f, false);
  lcm.publish(vehicle + AUTODRIVE_CH_COMMAND_SUFFIX, &stop);
  double pm, ym, po, yo;
  int nm, no;
  rms(b.map, b.gt, t0, t1, false, &pm, &ym, &nm);
  rms(b.odom, b.gt, t0, t1, true, &po, &yo, &no);
  double path_m = 0;
  for (std::size_t i = 1; i < b.gt.size(); ++i)
    if (b.gt[i].t_us >= t0 && b.gt[i].t_us <= t1)
      path_m += std::hypot(b.gt[i].x - b.gt[i - 1].x, b.gt[i].y - b.gt[i - 1].y);
  // The simulator's speed during the run (sim s per wall s): below 1 on a loaded machine.
  double rtf = NAN;
  std::pair<int64_t, int64_t> first{0, 0}, last{0, 0};
  for (const auto &p : b.clock_pairs)
    if (p.first >= t0 && p.first <= t1) {
      if (first.first == 0) first = p;
      last = p;
    }
  if (last.first > first.first)
    rtf = double(last.second - first.second) / double(last.first - first.first);
  std::printf(
      "{\"ekf_pos_rms_m\": %.4f, \"ekf_heading_rms_deg\": %.3f, "
      "\"ekf_pos_rms_m_no_eye\": %.4f, \"ekf_heading_rms_deg_no_eye\": %.3f, "
      "\"ekf_samples\": %d, \"ekf_path_m\": %.2f, \"ekf_collision\": %s, "
      "\"ekf_sim_real_time_factor\": %.3f}\n",
      pm, ym, po, yo, nm, path_m, b.collided ? "true" : "false", rtf);
  return nm > 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char **argv) {
  CLI::App app{"runtime-link-bench: measuring side of tools/bench link (see the file header)."};
  std::string mode, url = "udpm://239.255.76.67:7786?ttl=0", vehicle = AUTODRIVE_VEHICLE_DEFAULT,
                    pty, pwm_log, suffix;
  int samples = 500;
  int cpu_pid = 0;
  double seconds = 10, throttle = 0.6, steering = 0.6, eye_delay_ms = 50, flood_hz = 40000;
  double command_hz = 50;  // as the missions send (hil/missions/loop.py)
  std::string key_file;
  app.add_option("mode", mode, "serial | pwm | telemetry | ekf | flood")
      ->required()
      ->check(CLI::IsMember({"serial", "pwm", "telemetry", "ekf", "flood"}));
  app.add_option("--key-file", key_file,
                 "the car's command key (default: $AUTODRIVE_KEY_DIR/<VEH>.key, else "
                 "~/.config/autodrive/keys/<VEH>.key)");
  app.add_option("--flood-hz", flood_hz, "flood: commands per second on LCM")
      ->check(CLI::Range(1.0, 1e6))
      ->capture_default_str();
  app.add_option("--command-hz", command_hz,
                 "pwm: the controller's command rate between the steps [Hz]; above the "
                 "bridge's command_rate_hz its token bucket runs dry")
      ->check(CLI::Range(1.0, 1000.0))
      ->capture_default_str();
  app.add_option("--cpu-pid", cpu_pid, "flood: the process whose CPU time to report (the bridge)");
  app.add_option("--lcm-url", url, "LCM URL")->capture_default_str();
  app.add_option("--vehicle", vehicle, "vehicle name")->capture_default_str();
  app.add_option("--pty", pty, "serial: symlink for the fake Nano's pty");
  app.add_option("--pwm-log", pwm_log, "pwm: nano-simavr's --pwm-log file");
  app.add_option("--samples", samples, "serial/pwm: samples")->capture_default_str();
  app.add_option("--seconds", seconds, "telemetry: duration [s wall]; ekf: [s of sim time]")
      ->capture_default_str();
  app.add_option("--throttle", throttle, "ekf: loop throttle [-1, 1]")->capture_default_str();
  app.add_option("--steering", steering, "ekf: loop steering [-1, 1]")->capture_default_str();
  app.add_option("--eye-delay-ms", eye_delay_ms, "ekf: Eye pose latency [ms]")
      ->capture_default_str();
  app.add_option("--key-suffix", suffix, "telemetry: suffix for the JSON keys");
  CLI11_PARSE(app, argc, argv);
  if (mode != "telemetry") {
    try {
      g_signer.emplace(
          autodrive::auth::load_key(key_file.empty() ? autodrive::auth::default_key_path(vehicle)
                                                     : key_file),
          vehicle, "link-bench", autodrive::auth::kAuthorityMachine);
    } catch (const std::exception &e) {
      std::fprintf(stderr, "runtime-link-bench: %s\n", e.what());
      return 2;
    }
  }
  if (mode == "flood") return run_flood(url, vehicle, pty, seconds, flood_hz, cpu_pid);
  if (mode == "serial") return run_serial(url, vehicle, pty, samples);
  if (mode == "pwm") return run_pwm(url, vehicle, pwm_log, samples, command_hz);
  if (mode == "telemetry") return run_telemetry(url, vehicle, seconds, suffix);
  return run_ekf(url, vehicle, seconds, throttle, steering, eye_delay_ms);
}
