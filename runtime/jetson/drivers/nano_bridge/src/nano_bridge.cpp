#include <autodrive_channels.h>
#include <autodrive/nano_bridge/nano_bridge.hpp>

#include <autodrive/control_status_t.hpp>
#include <autodrive/imu_t.hpp>
#include <autodrive/log_limiter.hpp>
#include <autodrive/vehicle_command_t.hpp>
#include <autodrive/vehicle_state_t.hpp>
#include <lcm/lcm-cpp.hpp>
#include <poll.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cinttypes>
#include <cstdio>
#include <optional>

#include <autodrive/nano_bridge/bridge_convert.hpp>
#include <autodrive/nano_bridge/command_gate.hpp>
#include <autodrive/nano_bridge/command_pacer.hpp>
#include <autodrive/core/clock.hpp>
#include <autodrive_lcm/subscribe.hpp>
#include <autodrive/core/serial_port.hpp>
#include "protocol.h"

namespace autodrive::bridge {

const char *link_state_name(LinkState s) {
  switch (s) {
    case LinkState::no_device: return "no_device";
    case LinkState::handshaking: return "handshaking";
    case LinkState::linked: return "linked";
    case LinkState::refused: return "refused";
  }
  return "?";
}

namespace {
std::string hex32(uint32_t v) {
  char b[16];
  std::snprintf(b, sizeof b, "0x%08" PRIx32, v);
  return b;
}
}  // namespace

struct NanoBridge::Impl {
  autodrive::config::Config config;
  std::string tag;  // log prefix
  lcm::LCM lcm;
  autodrive::clock::Clock clock;
  autodrive::serial::SerialPort port;
  protocol_parser_t parser{};
  mutable std::mutex mu;  // guards status
  Status st;

  std::optional<autodrive::vehicle_command_t> latest_cmd;
  // sync_to_sim_clock: a command stamped later than the sim clock waits here for its tick
  std::optional<autodrive::vehicle_command_t> scheduled_cmd;
  int64_t scheduled_rx_us = 0;
  int64_t latest_cmd_rx_us = 0;     // command time (command_now_us)
  int64_t latest_cmd_clock_us = 0;  // the same arrival on `clock` (clock sim: its freshness)
  uint16_t cmd_seq = 0;
  uint8_t frame_seq = 0;
  int64_t next_tx_us = 0;       // next hello; sync_to_sim_clock: next frame [monotonic us]
  CommandPacer pacer;           // COMMAND frames: at once, capped, heartbeat when idle
  int64_t last_tick = -1;       // sync_to_sim_clock: the SIM_CLOCK tick last answered
  bool config_pending = false;  // sync_to_sim_clock: CONFIG goes out as the next tick's frame
  int64_t next_open_us = 0;
  int64_t last_rx_frame_us = 0;  // last good frame from the Nano [us, link_now_us]
  bool open_failure_logged = false;
  bool rejected_logged = false;
  // Receive side: what a noisy or hostile link produces is counted and logged at a limited
  // rate per device, never one line per frame.
  autodrive::LogLimiter rx_log{"receive problems"};
  protocol_stats_t rx_reported{};  // parser counters already logged
  // Command authentication: no key, no gate, and the bridge refuses to run (init_error).
  std::string key_file, key_error;
  std::optional<CommandGate> gate;
  int64_t next_control_us = 0;  // next CONTROL status [monotonic us]
  // Dropped commands: at most one line per second per source and reason, then a count.
  autodrive::LogLimiter drop_log{
      "dropped commands",
      autodrive::LogLimits{1, std::chrono::milliseconds(1000), spdlog::level::warn}};

  explicit Impl(const autodrive::config::Config &c)
      : config(c),
        tag("[bridge " + c.vehicle.name + "] "),
        lcm(c.lcm_url),
        clock(c.clock),
        pacer(c.bridge.command_burst_frames, c.bridge.command_rate_hz,
              static_cast<int64_t>(1e6 / c.bridge.heartbeat_hz)) {
    protocol_parser_init(&parser);
    key_file = c.bridge.command_key_file.empty() ? autodrive::auth::default_key_path(c.vehicle.name)
                                                 : c.bridge.command_key_file;
    try {
      gate.emplace(autodrive::auth::load_key(key_file), c.vehicle.name,
                   c.bridge.replay_window_ms * 1000LL, c.bridge.command_lease_ms * 1000LL,
                   autodrive::clock::wall_us());
    } catch (const autodrive::InputError &e) {
      key_error = std::string("bridge.command_key_file: ") + e.what();
    }
    if (lcm.good()) {
      autodrive_lcm::subscribe<autodrive::vehicle_command_t, Impl, &Impl::on_command>(
          lcm, c.vehicle.name + AUTODRIVE_CH_COMMAND_SUFFIX, this);
      clock.attach(lcm);
    }
  }

  LinkState state() const {
    std::lock_guard<std::mutex> g(mu);
    return st.state;
  }
  void set_state(LinkState s) {
    std::lock_guard<std::mutex> g(mu);
    st.state = s;
  }
  template <typename F>
  void count(F f) {
    std::lock_guard<std::mutex> g(mu);
    f(st);
  }

  int64_t heartbeat_period_us() const {
    return static_cast<int64_t>(1e6 / config.bridge.heartbeat_hz);
  }

  // The clock of the command path [us]: the control lease, command freshness, the token bucket
  // and the heartbeat. With bridge.sim_clock_commands (clock: sim) it is the simulator's
  // SIM_CLOCK, so the path behaves the same at any real-time factor (the emulated Nano's
  // failsafe runs on sim time too); else the monotonic clock. The serial link's hello and
  // reconnect timers stay monotonic: the pty is real whatever the clock.
  int64_t command_now_us() const {
    if (config.bridge.sim_clock_commands) return clock.now_us();
    return autodrive::clock::monotonic_us();
  }

  // The link timeout's clock [us]: with clock: sim the simulator's, because the emulated Nano
  // writes on sim time; a host too busy to step the sim for a wall second is not a lost link,
  // and the handshake it would start stops the commands long enough to latch the Nano's
  // failsafe (a car stuck in FAILSAFE under load, smart city at load 20-30). A dead sim closes
  // the pty, which lose_device() sees at once.
  int64_t link_now_us() const {
    return clock.sim() ? clock.now_us() : autodrive::clock::monotonic_us();
  }

  // The control lease's clock [us]: with clock: sim the simulator's, so a holder whose commands
  // come at its rate of sim time keeps its lease at any real-time factor (a frozen sim stops the
  // car through command_fresh instead); else the command path's.
  int64_t lease_now_us() const {
    if (clock.sim() && !config.bridge.sync_to_sim_clock) return clock.now_us();
    return command_now_us();
  }

  void log_drop(const autodrive::vehicle_command_t &m, Drop d) {
    // The source is what the sender claims: printable, bounded, and only for the log. Sources
    // a signature vouches for are few; unsigned ones all share one entry.
    std::string source = m.source.substr(0, autodrive::auth::kMaxSourceChars);
    for (char &ch : source)
      if (ch < 0x21 || ch > 0x7e) ch = '?';
    if (source.empty()) source = "(none)";
    const std::string key = d == Drop::unsigned_cmd || d == Drop::bad_mac
                                ? tag + "unauthenticated commands (" + drop_name(d) + ")"
                                : tag + "source '" + source + "' (" + drop_name(d) + ")";
    drop_log.event(key, "dropped a command from source '" + source + "'");
  }

  void publish_control() {
    const GateCounters &n = gate->counters();
    autodrive::control_status_t m{};
    m.utime = clock.now_us();
    m.holder = gate->holder();
    m.holder_authority = gate->holder_authority();
    m.holder_changes = n.holder_changes;
    m.applied = n.applied;
    m.dropped_unsigned = n.dropped_unsigned;
    m.dropped_bad_mac = n.dropped_bad_mac;
    m.dropped_replay = n.dropped_replay;
    m.dropped_not_holder = n.dropped_not_holder;
    m.last_dropped_source = n.last_dropped_source;
    lcm.publish(config.vehicle.name + AUTODRIVE_CH_CONTROL_SUFFIX, &m);
    count([&](Status &s) {
      s.control = n;
      s.holder = gate->holder();
    });
    next_control_us = autodrive::clock::monotonic_us() + 200000;  // 5 Hz
  }

  void holder_changed() {
    if (gate->holder().empty())
      spdlog::warn("{}control lease lapsed: no source holds control", tag);
    else
      spdlog::warn(
          "{}control now held by '{}' ({})", tag, gate->holder(),
          gate->holder_authority() == autodrive::auth::kAuthorityPerson ? "person" : "machine");
    publish_control();
  }

  void on_command(const autodrive::vehicle_command_t *m) {
    if (!gate) return;
    const int64_t now_cmd = command_now_us();
    const int64_t now_lease = lease_now_us();
    if (gate->expire(now_lease)) holder_changed();  // a lapse is published on its own
    const CommandGate::Verdict v = gate->admit(*m, now_lease, autodrive::clock::wall_us());
    if (v.holder_changed) holder_changed();
    if (v.drop != Drop::none) {
      if (v.drop != Drop::idle) log_drop(*m, v.drop);
      return;
    }
    const std::string why = command_problem(*m);
    if (!why.empty()) {
      // Rejected commands do not refresh the stream: a sender gone wrong disengages the car.
      count([](Status &s) { ++s.commands_rejected; });
      if (!rejected_logged) spdlog::warn("{}command rejected (seq {}): {}", tag, m->seq, why);
      rejected_logged = true;
      return;
    }
    rejected_logged = false;
    if (config.bridge.sync_to_sim_clock && m->utime > clock.now_us()) {
      // In step with SIM_CLOCK a command stamped in the future applies from that sim time, so
      // a scripted sender acts at the same tick in every run.
      scheduled_cmd = *m;
      scheduled_rx_us = now_cmd;
      return;
    }
    latest_cmd = *m;
    latest_cmd_rx_us = now_cmd;
    latest_cmd_clock_us = clock.now_us();
    // A fresh command goes to the Nano at once while the token bucket has a token; under a
    // flood the newest one waits for the next token (CommandPacer). In step with SIM_CLOCK
    // every frame waits for its tick instead.
    if (state() != LinkState::linked || config.bridge.sync_to_sim_clock) return;
    if (pacer.command(now_cmd)) {
      send_command(now_cmd);
      count([](Status &s) { ++s.commands_at_once; });
    } else {
      count([](Status &s) { ++s.commands_held; });
    }
  }

  void write_frame(uint8_t id, const uint8_t *payload, uint8_t len) {
    uint8_t frame[PROTOCOL_MAX_FRAME];
    const size_t n = protocol_frame_encode(id, frame_seq++, payload, len, frame, sizeof frame);
    const int r = port.write_all(frame, n);
    if (r < 0)
      lose_device(port.error());
    else if (r == 0)
      spdlog::warn("{}{}", tag, port.error());
  }

  // With clock: sim a command's freshness is judged in sim time (a run paced at 0.1x real time
  // keeps its commands fresh), and every command is stale on a frozen SIM_CLOCK
  // (Clock::kFrozenAfterUs of wall time). sim_clock_commands puts the whole command path on
  // SIM_CLOCK already, and sync_to_sim_clock keeps it monotonic (repeatable frames).
  bool command_fresh(int64_t now_us) const {
    if (!latest_cmd) return false;
    const int64_t timeout_us = config.bridge.command_timeout_ms * 1000LL;
    if (clock.sim() && !config.bridge.sync_to_sim_clock && !config.bridge.sim_clock_commands)
      return clock.fresh(latest_cmd_clock_us, timeout_us);
    return now_us - latest_cmd_rx_us <= timeout_us;
  }

  void send_command(int64_t now_us) {
    const bool fresh = command_fresh(now_us);
    const protocol_command_t c =
        make_command(latest_cmd ? &*latest_cmd : nullptr, fresh, cmd_seq++);
    uint8_t payload[PROTOCOL_LEN_COMMAND];
    protocol_command_pack(&c, payload);
    write_frame(PROTOCOL_ID_COMMAND, payload, PROTOCOL_LEN_COMMAND);
    count([&](Status &s) {
      ++s.commands_sent;
      if (c.flags & PROTOCOL_CMD_ENGAGED) ++s.engaged_sent;
    });
  }

  void send_hello_request() {
    write_frame(PROTOCOL_ID_HELLO_REQUEST, nullptr, 0);
    count([](Status &s) { ++s.hellos_sent; });
  }

  void send_config() {
    if (config.bridge.telemetry_period_ms == 0) return;
    protocol_config_t c{};
    c.servo_trim_us = static_cast<int16_t>(config.bridge.servo_trim_us);
    c.telemetry_period_ms = static_cast<uint16_t>(config.bridge.telemetry_period_ms);
    c.failsafe_timeout_ms = static_cast<uint16_t>(config.bridge.failsafe_timeout_ms);
    uint8_t payload[PROTOCOL_LEN_CONFIG];
    protocol_config_pack(&c, payload);
    write_frame(PROTOCOL_ID_CONFIG, payload, PROTOCOL_LEN_CONFIG);
  }

  // sync_to_sim_clock: one frame per SIM_CLOCK tick (the heartbeat period of sim time), sent
  // after everything the Nano wrote before the tick is read, so that with the simulator in
  // --lockstep-frames every frame reaches the firmware at the same sim step in every run.
  // Command freshness stays on the monotonic clock: a frozen sim still fails safe.
  void send_on_tick(int64_t now_us) {
    const int64_t tick = clock.now_us() / heartbeat_period_us();
    if (tick == last_tick) return;
    last_tick = tick;
    uint8_t buf[512];
    long n;
    while ((n = port.read_some(buf, sizeof buf)) > 0) feed(buf, static_cast<size_t>(n));
    if (n < 0) lose_device(port.error());
    if (!port.is_open()) return;
    if (scheduled_cmd && scheduled_cmd->utime <= clock.now_us()) {
      latest_cmd = scheduled_cmd;
      latest_cmd_rx_us = scheduled_rx_us;
      latest_cmd_clock_us = clock.now_us();
      scheduled_cmd.reset();
    }
    switch (state()) {
      case LinkState::linked:
        if (config_pending) {
          send_config();
          config_pending = false;
        } else {
          send_command(now_us);
        }
        break;
      case LinkState::handshaking:
      case LinkState::refused: send_hello_request(); break;
      case LinkState::no_device: break;
    }
  }

  void try_open(int64_t now_us) {
    if (now_us < next_open_us) return;
    next_open_us = now_us + config.bridge.reconnect_ms * 1000LL;
    const std::string why = port.open(config.bridge.device, config.bridge.baud);
    if (!why.empty()) {
      if (!open_failure_logged)
        spdlog::warn("{}cannot open the Nano: {}; retrying every {} ms", tag, why,
                     config.bridge.reconnect_ms);
      open_failure_logged = true;
      return;
    }
    open_failure_logged = false;
    spdlog::info("{}opened {} at {} baud; handshaking", tag, config.bridge.device,
                 config.bridge.baud);
    protocol_parser_init(&parser);
    rx_reported = protocol_stats_t{};
    count([](Status &s) {
      ++s.opens;
      s.state = LinkState::handshaking;
    });
    next_tx_us = now_us;
    last_rx_frame_us = link_now_us();
  }

  void lose_device(const std::string &why) {
    if (!port.is_open()) return;
    spdlog::warn("{}lost the Nano: {}; reopening {} every {} ms", tag, why, config.bridge.device,
                 config.bridge.reconnect_ms);
    port.close();
    count([](Status &s) {
      ++s.disconnects;
      s.state = LinkState::no_device;
    });
    next_open_us = autodrive::clock::monotonic_us() + config.bridge.reconnect_ms * 1000LL;
  }

  HostLinkStats host_stats() const {
    HostLinkStats h;
    h.frames_ok = parser.stats.frames_ok;
    h.bad_crc = parser.stats.bad_crc;
    h.dropped = parser.stats.frames_dropped;
    return h;
  }

  void on_hello(const protocol_frame_t &f, int64_t now_us) {
    protocol_hello_t h{};
    if (protocol_hello_unpack(f.payload, f.len, &h) != 0) return bad_payload("HELLO", f.len);
    const uint32_t ours = protocol_schema_hash();
    if (h.schema_hash != ours || h.proto_version != PROTOCOL_VERSION) {
      const std::string msg = "schema mismatch on " + config.bridge.device +
                              ": the Nano (firmware " + std::to_string(h.fw_major) + "." +
                              std::to_string(h.fw_minor) + "." + std::to_string(h.fw_patch) +
                              ") speaks protocol v" + std::to_string(h.proto_version) + " schema " +
                              hex32(h.schema_hash) + ", this runtime speaks protocol v" +
                              std::to_string(PROTOCOL_VERSION) + " schema " + hex32(ours) +
                              "; link refused (flash matching firmware or rebuild the runtime)";
      spdlog::error("{}{}", tag, msg);
      count([&](Status &s) {
        ++s.refusals;
        s.last_refusal = msg;
        s.state = LinkState::refused;
      });
      next_tx_us = now_us + config.bridge.refused_retry_ms * 1000LL;
      return;
    }
    if (state() == LinkState::linked) return;  // a repeated HELLO: already linked
    spdlog::info("{}linked: Nano firmware {}.{}.{} build {}, protocol v{} schema {}", tag,
                 h.fw_major, h.fw_minor, h.fw_patch, h.build_id, h.proto_version,
                 hex32(h.schema_hash));
    count([](Status &s) {
      ++s.handshakes;
      s.state = LinkState::linked;
    });
    if (config.bridge.sync_to_sim_clock)
      config_pending = true;
    else
      send_config();
    next_tx_us = now_us;
    pacer.restart(command_now_us());
  }

  void on_state(const protocol_frame_t &f) {
    protocol_state_t s{};
    if (protocol_state_unpack(f.payload, f.len, &s) != 0) return bad_payload("STATE", f.len);
    const std::string problem = state_problem(s);
    if (!problem.empty()) {
      count([](Status &st2) { ++st2.rx_bad_payload; });
      rx_log.event(config.bridge.device, "implausible STATE dropped: " + problem);
      return;
    }
    const int64_t t = clock.now_us();
    autodrive::vehicle_state_t vs{};
    fill_state(s, config.vehicle, host_stats(), t, &vs);
    lcm.publish(config.vehicle.name + AUTODRIVE_CH_STATE_SUFFIX, &vs);
    bool imu = (s.faults & PROTOCOL_FAULT_IMU_LOST) == 0;
    if (imu) {
      autodrive::imu_t m{};
      fill_imu(s, config.bridge, t, &m);
      lcm.publish(config.vehicle.name + AUTODRIVE_CH_IMU_SUFFIX, &m);
    }
    count([&](Status &st2) {
      ++st2.states_published;
      if (imu) ++st2.imu_published;
    });
  }

  void bad_payload(const char *what, unsigned len) {
    count([](Status &s) { ++s.rx_bad_payload; });
    rx_log.event(
        config.bridge.device,
        fmt::format("{} frame with a {}-byte payload does not unpack: dropped", what, len));
  }

  // Feeds received bytes to the parser; counts and logs (limited) any new garbage.
  void feed(const uint8_t *buf, size_t n) {
    protocol_parser_feed(&parser, buf, n, &Impl::on_frame, this);
    const protocol_stats_t &p = parser.stats;
    const uint32_t skipped = p.skipped_bytes - rx_reported.skipped_bytes;
    const uint32_t crc = p.bad_crc - rx_reported.bad_crc;
    const uint32_t len = p.bad_length - rx_reported.bad_length;
    if (skipped == 0 && crc == 0 && len == 0) return;
    rx_reported = p;
    count([&](Status &s) {
      s.rx_skipped_bytes += skipped;
      s.rx_bad_crc += crc;
      s.rx_bad_length += len;
    });
    rx_log.event(config.bridge.device,
                 fmt::format("garbage from the Nano: {} bytes skipped, {} bad CRC, {} bad length",
                             skipped, crc, len));
  }

  static void on_frame(const protocol_frame_t *f, void *ctx) {
    auto *self = static_cast<Impl *>(ctx);
    const int64_t now = autodrive::clock::monotonic_us();
    self->last_rx_frame_us = self->link_now_us();
    const LinkState s = self->state();
    if (f->id == PROTOCOL_ID_HELLO) {
      self->on_hello(*f, now);
    } else if (f->id == PROTOCOL_ID_STATE && s == LinkState::linked) {
      // Telemetry counts only from a Nano whose schema we checked.
      self->on_state(*f);
    } else if (f->id == PROTOCOL_ID_NACK) {
      protocol_nack_t n{};
      if (protocol_nack_unpack(f->payload, f->len, &n) == 0) {
        self->count([](Status &st2) { ++st2.nacks; });
        self->rx_log.event(self->config.bridge.device,
                           fmt::format("Nano refused frame id 0x{:02x} seq {}: reason {}",
                                       n.rejected_id, n.seq, n.reason));
      } else {
        self->bad_payload("NACK", f->len);
      }
    }
  }

  void poll_once(const std::atomic<bool> &stop) {
    const int64_t now = autodrive::clock::monotonic_us();
    if (!port.is_open()) try_open(now);

    struct pollfd fds[2];
    int nfds = 0;
    fds[nfds++] = {lcm.getFileno(), POLLIN, 0};
    if (port.is_open()) fds[nfds++] = {port.fd(), POLLIN, 0};
    int64_t wait_us = 20000;
    if (port.is_open()) {
      // On the sim clock the next frame comes with a SIM_CLOCK message: the LCM wake-up.
      int64_t due_us = next_tx_us - now;
      if (state() == LinkState::linked && !config.bridge.sync_to_sim_clock)
        due_us = config.bridge.sim_clock_commands ? wait_us : pacer.next_due_us() - now;
      wait_us = std::min<int64_t>(wait_us, std::max<int64_t>(0, due_us));
    }
    const int r = ::poll(fds, static_cast<nfds_t>(nfds), static_cast<int>(wait_us / 1000));
    if (stop) return;
    // Drain what LCM has (bounded, so the serial side is served even under a flood).
    if (r > 0 && (fds[0].revents & POLLIN))
      for (int i = 0; i < 512 && lcm.handleTimeout(0) > 0; ++i) {
      }
    if (gate) {
      drop_log.flush();
      if (gate->expire(lease_now_us())) holder_changed();
      if (autodrive::clock::monotonic_us() >= next_control_us) publish_control();
    }
    if (r > 0 && nfds == 2 && port.is_open()) {
      if (fds[1].revents & POLLIN) {
        uint8_t buf[512];
        const long n = port.read_some(buf, sizeof buf);
        if (n < 0)
          lose_device(port.error());
        else if (n > 0)
          feed(buf, static_cast<size_t>(n));
      } else if (fds[1].revents & (POLLHUP | POLLERR | POLLNVAL)) {
        lose_device(config.bridge.device + ": hang-up (unplugged, or the peer closed it)");
      }
    }
    if (!port.is_open()) return;

    const int64_t t = autodrive::clock::monotonic_us();
    const LinkState s = state();
    if (s == LinkState::linked &&
        link_now_us() - last_rx_frame_us > config.bridge.link_timeout_ms * 1000LL) {
      spdlog::warn("{}no frame from the Nano for {} ms{}; handshaking again", tag,
                   config.bridge.link_timeout_ms, clock.sim() ? " of sim time" : "");
      set_state(LinkState::handshaking);
      next_tx_us = t;
    }
    if (config.bridge.sync_to_sim_clock) {
      send_on_tick(t);
      return;
    }
    if (state() == LinkState::linked) {
      // A held command once a token is back, else the heartbeat after a quiet period.
      const int64_t tc = command_now_us();
      if (pacer.due(tc)) send_command(tc);
      return;
    }
    if (t < next_tx_us) return;
    switch (state()) {
      case LinkState::linked: break;
      case LinkState::handshaking:
        send_hello_request();
        next_tx_us = t + config.bridge.hello_retry_ms * 1000LL;
        break;
      case LinkState::refused:
        send_hello_request();  // the Nano may be reflashed meanwhile
        next_tx_us = t + config.bridge.refused_retry_ms * 1000LL;
        break;
      case LinkState::no_device: break;
    }
  }
};

NanoBridge::NanoBridge(const autodrive::config::Config &config)
    : impl_(std::make_unique<Impl>(config)) {}
NanoBridge::~NanoBridge() = default;

std::string NanoBridge::init_error() const {
  if (!impl_->config.has_bridge) return impl_->config.file + ": bridge: missing section";
  if (!impl_->key_error.empty()) return impl_->config.file + ": " + impl_->key_error;
  if (!impl_->lcm.good())
    return "LCM URL '" + impl_->config.lcm_url +
           "' unusable (for udpm on a host with no multicast route: ip route add 239.0.0.0/8 dev "
           "lo)";
  return "";
}

void NanoBridge::run(const std::atomic<bool> &stop) {
  while (!stop) {
    impl_->poll_once(stop);
    impl_->rx_log.flush();
    autodrive_lcm::malformed_log().flush();
  }
  impl_->port.close();
}

Status NanoBridge::status() const {
  std::lock_guard<std::mutex> g(impl_->mu);
  return impl_->st;
}

}  // namespace autodrive::bridge
