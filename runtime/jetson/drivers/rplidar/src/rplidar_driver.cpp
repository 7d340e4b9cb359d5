#include <autodrive_channels.h>
#include <autodrive/rplidar/rplidar_driver.hpp>

#include <lcm/lcm-cpp.hpp>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/ioctl.h>

#include <autodrive/log_limiter.hpp>

#include <deque>
#include <mutex>

#include <autodrive/core/clock.hpp>
#include <autodrive/core/serial_port.hpp>
#include <autodrive/rplidar/rplidar_decoder.hpp>

namespace autodrive::rplidar {

struct Driver::Impl {
  enum class Phase { closed, health, scan };
  autodrive::config::Config config;
  std::string tag;
  lcm::LCM lcm;
  autodrive::clock::Clock clock;
  autodrive::serial::SerialPort port;
  Decoder decoder;
  ScanAssembler assembler;
  mutable std::mutex mu;
  DriverStatus st;
  Phase phase = Phase::closed;
  int64_t deadline_us = 0;  // current phase times out here [monotonic us]
  int64_t next_open_us = 0;
  int64_t last_node_us = 0;
  int64_t next_report_us = 0;  // next statistics log line [monotonic us]
  bool open_failure_logged = false;
  // A device (or a forger on the line) reporting errors must not reset the A1 forever nor
  // flood the log: at most kMaxResets resets per kResetWindowUs, health lines rate-limited.
  static constexpr int kMaxResets = 3;
  static constexpr int64_t kResetWindowUs = 60000000;
  std::deque<int64_t> reset_times_us;
  autodrive::LogLimiter health_log{"health reports"};

  explicit Impl(const autodrive::config::Config &c)
      : config(c),
        tag("[lidar " + c.vehicle.name + "] "),
        lcm(c.lcm_url),
        clock(c.clock),
        assembler(ScanParams{c.lidar.frame_id, c.lidar.mount_yaw_rad, c.lidar.range_min_m,
                             c.lidar.range_max_m}) {
    if (lcm.good()) clock.attach(lcm);
    decoder.on_health = [this](const Health &h) { on_health(h); };
    decoder.on_node = [this](const Node &n) { on_node(n); };
  }

  void send(uint8_t cmd) {
    const auto req = request(cmd);
    if (port.write_all(req.data(), req.size()) < 0) lose(port.error());
  }

  void start_health(int64_t now) {
    send(kCmdStop);
    decoder.reset();
    send(kCmdGetHealth);
    phase = Phase::health;
    deadline_us = now + 1000000;
  }

  void start_scan(int64_t now) {
    decoder.reset();
    send(kCmdScan);
    phase = Phase::scan;
    last_node_us = now;
    std::lock_guard<std::mutex> g(mu);
    ++st.scan_starts;
  }

  void on_health(const Health &h) {
    const std::string &device = config.lidar.device;
    if (phase != Phase::health) {
      // Nobody asked: a health packet in the scan stream is noise or forged.
      {
        std::lock_guard<std::mutex> g(mu);
        ++st.unsolicited_health;
      }
      health_log.event(device, fmt::format("unsolicited health packet (status {}, code "
                                           "0x{:04x}) ignored",
                                           h.status, h.error_code));
      return;
    }
    {
      std::lock_guard<std::mutex> g(mu);
      st.last_health = h.status;
    }
    const int64_t now = autodrive::clock::monotonic_us();
    if (h.status == 2) {
      while (!reset_times_us.empty() && now - reset_times_us.front() > kResetWindowUs)
        reset_times_us.pop_front();
      if (static_cast<int>(reset_times_us.size()) >= kMaxResets) {
        {
          std::lock_guard<std::mutex> g(mu);
          ++st.resets_refused;
        }
        health_log.event(device, fmt::format("device reports error code 0x{:04x}; already "
                                             "reset {} times in {} s, asking again in 5 s",
                                             h.error_code, kMaxResets, kResetWindowUs / 1000000));
        deadline_us = now + 5000000;
        return;
      }
      reset_times_us.push_back(now);
      health_log.event(
          device, fmt::format("device reports error code 0x{:04x}; resetting it", h.error_code));
      {
        std::lock_guard<std::mutex> g(mu);
        ++st.resets;
      }
      send(kCmdReset);
      deadline_us = now + 2000000;  // the A1 needs time to reboot before it answers again
      return;
    }
    if (h.status == 1)
      health_log.event(device, fmt::format("device health warning 0x{:04x}", h.error_code));
    start_scan(now);
  }

  void on_node(const Node &n) {
    const int64_t now = autodrive::clock::monotonic_us();
    last_node_us = now;
    autodrive::lidar_scan_t scan;
    if (assembler.add(n, clock.now_us(), &scan)) {
      lcm.publish(config.vehicle.name + AUTODRIVE_CH_LIDAR_SUFFIX, &scan);
      std::lock_guard<std::mutex> g(mu);
      ++st.scans_published;
    }
  }

  void try_open(int64_t now) {
    if (now < next_open_us) return;
    next_open_us = now + 1000000;
    const std::string why = port.open(config.lidar.device, config.lidar.baud);
    if (!why.empty()) {
      if (!open_failure_logged)
        spdlog::warn("{}cannot open the RPLIDAR: {}; retrying every 1 s", tag, why);
      open_failure_logged = true;
      return;
    }
    open_failure_logged = false;
    // The A1's motor runs while DTR is low (on a pty this ioctl fails harmlessly).
    int dtr = TIOCM_DTR;
    ioctl(port.fd(), TIOCMBIC, &dtr);
    spdlog::info("{}opened {} at {} baud", tag, config.lidar.device, config.lidar.baud);
    {
      std::lock_guard<std::mutex> g(mu);
      ++st.opens;
    }
    start_health(now);
  }

  void lose(const std::string &why) {
    if (!port.is_open()) return;
    spdlog::warn("{}lost the RPLIDAR: {}; reopening every 1 s", tag, why);
    port.close();
    phase = Phase::closed;
    next_open_us = autodrive::clock::monotonic_us() + 1000000;
    std::lock_guard<std::mutex> g(mu);
    ++st.disconnects;
  }

  void poll_once() {
    const int64_t now = autodrive::clock::monotonic_us();
    if (!port.is_open()) try_open(now);
    struct pollfd fds[2];
    nfds_t nfds = 0;
    fds[nfds++] = {lcm.getFileno(), POLLIN, 0};
    if (port.is_open()) fds[nfds++] = {port.fd(), POLLIN, 0};
    const int r = ::poll(fds, nfds, 20);
    if (r > 0 && (fds[0].revents & POLLIN)) lcm.handleTimeout(0);
    if (r > 0 && nfds == 2 && port.is_open()) {
      if (fds[1].revents & POLLIN) {
        uint8_t buf[1024];
        const long n = port.read_some(buf, sizeof buf);
        if (n < 0)
          lose(port.error());
        else if (n > 0)
          decoder.feed(buf, static_cast<std::size_t>(n));
      } else if (fds[1].revents & (POLLHUP | POLLERR | POLLNVAL)) {
        lose(config.lidar.device + ": hang-up");
      }
    }
    if (!port.is_open()) return;
    const int64_t t = autodrive::clock::monotonic_us();
    if (phase == Phase::health && t > deadline_us) {
      health_log.event(config.lidar.device, "no health answer; asking again");
      start_health(t);
    } else if (phase == Phase::scan && t - last_node_us > 2000000) {
      spdlog::warn("{}no measurement for 2 s; restarting the scan", tag);
      start_health(t);
    }
    if (t >= next_report_us) {
      // A periodic health line: what the link carried and what was published.
      const DecoderStats &d = decoder.stats();
      spdlog::info("{}nodes {} bad {} skipped bytes {} descriptors {} scans published {}", tag,
                   d.nodes, d.bad_nodes, d.skipped_bytes, d.descriptors, assembler.scans());
      next_report_us = t + 10000000;
    }
    health_log.flush();
    std::lock_guard<std::mutex> g(mu);
    st.scanning = decoder.scanning();
    st.nodes = decoder.stats().nodes;
    st.bad_nodes = decoder.stats().bad_nodes;
  }
};

Driver::Driver(const autodrive::config::Config &config) : impl_(std::make_unique<Impl>(config)) {}
Driver::~Driver() = default;

std::string Driver::init_error() const {
  if (!impl_->config.has_lidar) return impl_->config.file + ": lidar: missing section";
  if (!impl_->lcm.good()) return "LCM URL '" + impl_->config.lcm_url + "' unusable";
  return "";
}

void Driver::run(const std::atomic<bool> &stop) {
  while (!stop) impl_->poll_once();
  if (impl_->port.is_open()) impl_->send(kCmdStop);
  impl_->port.close();
}

DriverStatus Driver::status() const {
  std::lock_guard<std::mutex> g(impl_->mu);
  return impl_->st;
}

}  // namespace autodrive::rplidar
