#include <autodrive/v2v/v2v_node.hpp>

#include <autodrive/odometry_t.hpp>
#include <autodrive/v2v/v2v_peers.hpp>
#include <autodrive/v2v_state_t.hpp>
#include <autodrive/v2x.hpp>
#include <autodrive/vehicle_state_t.hpp>
#include <autodrive_channels.h>
#include <lcm/lcm-cpp.hpp>
#include <spdlog/spdlog.h>

#include <chrono>

#include <autodrive_lcm/subscribe.hpp>

namespace autodrive::v2v {

namespace {
constexpr int64_t kStatusPeriodUs = 5000000;  // status log period [us of message time]
}

struct V2vNode::Impl {
  autodrive::config::Config config;
  lcm::LCM lcm;
  autodrive::clock::Clock clock;  // peers' age: SIM_CLOCK with clock sim, else wall time
  autodrive::v2v::PeerTable peers;
  autodrive::vehicle_state_t state{};
  bool have_state = false;
  int64_t period_us;
  int64_t next_pub_us = 0, next_status_us = 0;  // [us, pose stamps]
  int32_t seq = 0;
  // The car signs its broadcast with its own certificate (NIGELk.cert) and takes a peer's only
  // when signed by that peer's certificate.
  std::optional<autodrive::v2x::Signer> signer;
  std::optional<autodrive::v2x::Verifier> verifier;

  explicit Impl(const autodrive::config::Config &c)
      : config(c),
        lcm(c.lcm_url),
        clock(c.clock),
        peers(c.vehicle.name, static_cast<int64_t>(c.v2v_stale_ms) * 1000),
        period_us(c.v2v_hz > 0 ? static_cast<int64_t>(1e6 / c.v2v_hz) : 0) {
    if (!lcm.good()) return;
    clock.attach(lcm);
    if (period_us == 0) return;
    // Without a certificate the car is not on V2V (nobody would take its unsigned states):
    // said loudly at the start and in every status line, and the rest of the runtime runs.
    signer = autodrive::v2x::Signer::load("autodrive-runtime V2V", c.vehicle.name);
    verifier = autodrive::v2x::Verifier::load("autodrive-runtime V2V");
    if (!signer || !verifier) {
      spdlog::error("{} V2V: OFF, no usable certificate (tools/keys issue --name {} --role car)",
                    c.vehicle.name, c.vehicle.name);
      return;
    }
    const std::string v = c.vehicle.name;
    autodrive_lcm::subscribe<autodrive::odometry_t, Impl, &Impl::on_pose>(
        lcm, v + AUTODRIVE_CH_POSE_MAP_SUFFIX, this);
    autodrive_lcm::subscribe<autodrive::vehicle_state_t, Impl, &Impl::on_vehicle_state>(
        lcm, v + AUTODRIVE_CH_STATE_SUFFIX, this);
    autodrive_lcm::subscribe<autodrive::v2v_state_t, Impl, &Impl::on_peer>(lcm, AUTODRIVE_CH_V2V,
                                                                           this);
  }

  void on_vehicle_state(const autodrive::vehicle_state_t *m) {
    state = *m;
    have_state = true;
  }

  void on_peer(const autodrive::v2v_state_t *m) {
    if (m->vehicle == config.vehicle.name) return;  // our own broadcast
    const int64_t now = clock.now_us();
    if (verifier->accept(AUTODRIVE_CH_V2V, *m, AUTODRIVE_CH_V2V_SIGNED_BY, m->vehicle.c_str(), now))
      peers.on_state(*m, now);
  }

  void on_pose(const autodrive::odometry_t *m) {
    if (!signer || !verifier) return;
    // A quarter period of slack so that the 100 Hz pose stream's jitter skips no broadcast.
    if (next_pub_us == 0 || m->utime >= next_pub_us - period_us / 4) {
      next_pub_us = (next_pub_us == 0 ? m->utime : next_pub_us) + period_us;
      if (next_pub_us < m->utime) next_pub_us = m->utime + period_us;  // fell behind
      broadcast(*m);
    }
    if (m->utime >= next_status_us) {
      if (next_status_us != 0) {
        const auto fresh = peers.fresh(clock);
        const std::string refused = verifier->summary();
        spdlog::info("{} V2V: {} broadcasts, {}; refused: {}", config.vehicle.name, seq,
                     autodrive::v2v::status_line(fresh, peers.dropped_stale()),
                     refused.empty() ? "none" : refused);
      }
      next_status_us = m->utime + kStatusPeriodUs;
    }
  }

  void broadcast(const autodrive::odometry_t &p) {
    autodrive::v2v_state_t s{};
    s.utime = p.utime;
    s.seq = seq++;
    s.vehicle = config.vehicle.name;
    s.x_m = p.x_m;
    s.y_m = p.y_m;
    s.yaw_rad = p.yaw_rad;
    s.speed_m_s = p.vx_m_s;
    s.yaw_rate_rad_s = p.yaw_rate_rad_s;
    if (have_state) {
      s.throttle = state.throttle_applied;
      s.steering = state.steering_applied;
      s.indicators = state.indicators;
    }
    s.route = config.route;
    s.route_s_m = -1.0f;  // the runtime does not follow the route itself
    signer->sign(AUTODRIVE_CH_V2V, s, p.utime);
    lcm.publish(AUTODRIVE_CH_V2V, &s);
  }
};

V2vNode::V2vNode(const autodrive::config::Config &config) : impl_(std::make_unique<Impl>(config)) {}
V2vNode::~V2vNode() = default;

std::string V2vNode::init_error() const {
  if (impl_->config.v2v_hz <= 0) return impl_->config.file + ": v2v_hz: 0 (V2V is off)";
  if (!impl_->lcm.good()) return "LCM URL '" + impl_->config.lcm_url + "' unusable";
  return "";
}

void V2vNode::run(const std::atomic<bool> &stop) {
  bool said = false;
  const auto t0 = std::chrono::steady_clock::now();
  while (!stop) {
    impl_->lcm.handleTimeout(20);
    autodrive_lcm::malformed_log().flush();
    if (!said && impl_->seq == 0 &&
        std::chrono::steady_clock::now() - t0 > std::chrono::seconds(5)) {
      said = true;
      spdlog::warn(
          "{} V2V: no {} pose yet (no Eye and no estimator.initial_pose_map): not "
          "broadcasting",
          impl_->config.vehicle.name, impl_->config.vehicle.name + AUTODRIVE_CH_POSE_MAP_SUFFIX);
    }
  }
}

}  // namespace autodrive::v2v
