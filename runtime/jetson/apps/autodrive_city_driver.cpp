// autodrive-city-driver: the smart-city behaviour layer of one car. Follows a route along the
// map's lanes with the runtime's EKF pose (<VEH>_POSE_MAP), obeys lights (from the V2I advisory
// on <VEH>_V2I; stale -> every light red), stop signs, speed limits and curve signs (from the
// map's sidecar JSON), keeps a gap behind cars ahead (V2V peers), stops for obstacles on its
// path (the runtime's <VEH>_LIDAR scan; no fresh scan = blocked), and drives through the
// runtime's guarded path: signed <VEH>_COMMAND (autodrive::auth::Signer), 50 Hz of car time.
// Its clock (--clock wall|sim, autodrive::clock::Clock) judges the advisory's and the peers'
// age; with --clock sim a frozen SIM_CLOCK (no tick for Clock::kFrozenAfterUs of monotonic
// time) makes the driver send disengaged stops only.
#include <autodrive/core/clock.hpp>
#include <CLI/CLI.hpp>
#include <autodrive/instance.hpp>
#include <autodrive/command_auth.hpp>
#include <autodrive/lidar_scan_t.hpp>
#include <autodrive/odometry_t.hpp>
#include <autodrive/v2i_advisory_t.hpp>
#include <autodrive/v2v/peer_account.hpp>
#include <autodrive/v2v/v2v_peers.hpp>
#include <autodrive/v2v_state_t.hpp>
#include <autodrive/v2x.hpp>
#include <autodrive/vehicle_command_t.hpp>
#include <autodrive_channels.h>
#include <autodrive_vehicle.h>
#include <lcm/lcm-cpp.hpp>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <optional>
#include <thread>

#include <autodrive_lcm/subscribe.hpp>

#include <autodrive/autonomy/pure_pursuit.hpp>
#include <autodrive/behaviour/city_map.hpp>
#include <autodrive/behaviour/city_rules.hpp>
#include <autodrive/behaviour/obstacle.hpp>
#include <autodrive/pure_pursuit.hpp>

namespace {

std::atomic<bool> g_stop{false};
void on_signal(int) {
  g_stop = true;
}

struct Options {
  std::string map, route, vehicle = "NIGEL1", lcm_url, key_file;
  autodrive::config::ClockMode clock = autodrive::config::ClockMode::wall;
  double lookahead_m = 0.2, speed_kp = 1.5, advisory_stale_ms = 500;
  double status_period_s = 2.0;
  double scan_stale_ms = 500;  // a scan older than this [ms, car time]: no fresh scan
  bool lidar = true;
  autodrive::behaviour::RulesConfig rules;
  autodrive::behaviour::ObstacleConfig obstacles;
};

class Driver {
 public:
  Driver(const Options &o, const autodrive::behaviour::Track &track, lcm::LCM &lcm,
         autodrive::auth::Signer signer, autodrive::v2x::Verifier verifier)
      : o_(o),
        track_(track),
        rules_(track_, o.rules),
        lcm_(lcm),
        signer_(std::move(signer)),
        clock_(o.clock),
        verifier_(std::move(verifier)),
        peers_(o.vehicle) {
    clock_.attach(lcm_);
  }

  void on_pose(const autodrive::odometry_t *m) {
    now_us_ = m->utime;
    // Progress along the track, searched near the last one (crossing tracks never jump).
    const auto p = autodrive::behaviour::project(track_, m->x_m, m->y_m, have_s_ ? s_local_ : -1.0);
    if (have_s_ && track_.loop && p.s_m < s_local_ - 0.5 * track_.length_m) {
      ++lap_;
      std::printf("[city-driver] %s: lap %ld done at t=%.2f s\n", o_.vehicle.c_str(), lap_,
                  m->utime * 1e-6);
    }
    s_local_ = p.s_m;
    have_s_ = true;
    pose_ = {m->x_m, m->y_m, m->yaw_rad, s_local_};
    if (last_cmd_us_ != 0 && m->utime - last_cmd_us_ < 19000) return;  // 50 Hz
    last_cmd_us_ = m->utime;
    if (clock_.frozen()) {  // no time to judge anything by (no or a stopped SIM_CLOCK): stop
      send(false, 0.0, 0.0);
      return;
    }
    const double s = s_local_ + lap_ * track_.length_m;
    autodrive::behaviour::RulesInput in;
    in.s_m = s;
    in.speed_m_s = m->vx_m_s;
    in.t_us = m->utime;
    in.advisory = advisory();
    if (o_.lidar) {
      in.scan_fresh = scan_us_ > 0 && m->utime - scan_us_ <= o_.scan_stale_ms * 1e3;
      in.obstacle_ahead_m = obstacle_.ahead_m(track_, s_local_);
    }
    const auto fresh = peers_.fresh(clock_);
    const std::vector<int> ahead_of = peers_ahead(fresh, in.peers_ahead_m);
    const auto out = rules_.step(in);
    account_.step(m->utime, fresh, out.peer_index < 0 ? -1 : ahead_of[out.peer_index]);
    // Speed: the open-loop throttle map of the autonomy's tracker plus a P term on the EKF speed.
    const double top_m_s = autodrive::autonomy::TrackerConfig{}.top_speed_m_s;
    double throttle = 0.0;
    if (out.speed_m_s > 0.005)
      throttle =
          std::clamp(out.speed_m_s / top_m_s + o_.speed_kp * (out.speed_m_s - m->vx_m_s), 0.0, 1.0);
    // Steering: pure pursuit on the track point one lookahead ahead.
    const auto goal = autodrive::behaviour::point_at(track_, s_local_ + o_.lookahead_m);
    const double delta =
        autodrive::pursuit_steer_rad(m->x_m, m->y_m, m->yaw_rad, goal.x_m, goal.y_m);
    send(true, throttle, delta / AUTODRIVE_VEHICLE_STEER_LIMIT_RAD);
    if (m->utime - last_status_us_ >= static_cast<int64_t>(o_.status_period_s * 1e6)) {
      last_status_us_ = m->utime;
      std::printf("[city-driver] %s t=%.1f s lap %ld s=%.2f/%.2f m v=%.3f m/s -> %.3f m/s (%s)%s\n",
                  o_.vehicle.c_str(), m->utime * 1e-6, lap_, s_local_, track_.length_m, m->vx_m_s,
                  out.speed_m_s, out.reason.c_str(), in.advisory.fresh ? "" : " [advisory stale]");
      std::fflush(stdout);
    }
  }

  // The fresh peers on the track ahead: their distance along it [m] into ahead_m, and for each
  // its index in fresh (returned).
  std::vector<int> peers_ahead(const std::vector<autodrive::v2v_state_t> &fresh,
                               std::vector<double> &ahead_m) const {
    std::vector<int> index;
    for (size_t k = 0; k < fresh.size(); ++k) {
      const auto q = autodrive::behaviour::project(track_, fresh[k].x_m, fresh[k].y_m, s_local_,
                                                   0.0, o_.rules.peer_horizon_m);
      double ahead = q.s_m - s_local_;
      if (track_.loop && ahead < 0) ahead += track_.length_m;
      if (q.dist_m < o_.rules.peer_corridor_m && ahead > 0 && ahead < o_.rules.peer_horizon_m) {
        ahead_m.push_back(ahead);
        index.push_back(static_cast<int>(k));
      }
    }
    return index;
  }

  // Only the SCM's signed, fresh advisory (on the car's clock) counts: a forged GREEN is dropped.
  void on_advisory(const autodrive::v2i_advisory_t *m) {
    if (m->vehicle != o_.vehicle) return;
    if (!verifier_.accept(o_.vehicle + AUTODRIVE_CH_V2I_SUFFIX, *m, AUTODRIVE_CH_V2I_SIGNED_BY,
                          nullptr, clock_.now_us()))
      return;
    adv_ = *m;
    adv_at_us_ = clock_.now_us();
    have_adv_ = true;
  }

  // A peer counts only when signed by the car it names (no ghost cars, no borrowed names); the
  // account keeps which certificate signed it.
  void on_peer(const autodrive::v2v_state_t *m) {
    if (m->vehicle == o_.vehicle) return;  // our own broadcast: the peer table skips it
    const int64_t now = clock_.now_us();
    v2x_sender_t sender{};
    if (!verifier_.accept(AUTODRIVE_CH_V2V, *m, AUTODRIVE_CH_V2V_SIGNED_BY, m->vehicle.c_str(), now,
                          &sender))
      return;
    account_.accepted(*m, sender.serial);
    peers_.on_state(*m, now);
  }

  // Judged at once with the latest pose (the scan is ~1/7 s long; the margin covers that).
  void on_scan(const autodrive::lidar_scan_t *m) {
    if (!have_s_) return;
    autodrive::behaviour::Scan scan;
    scan.angle_min_rad = m->angle_min_rad;
    scan.angle_increment_rad = m->angle_increment_rad;
    scan.range_min_m = m->range_min_m;
    scan.range_max_m = m->range_max_m;
    scan.ranges_m = m->ranges_m;
    obstacle_.on_scan(track_, pose_, scan, o_.obstacles, o_.rules.front_m);
    scan_us_ = m->utime;
  }

  std::string refused_summary() const { return verifier_.summary(); }
  std::string peer_account() const { return account_.json(); }

  void send(bool engaged, double throttle, double steering) {
    autodrive::vehicle_command_t c{};
    c.utime = now_us_;
    c.seq = seq_++;
    c.throttle = static_cast<float>(throttle);
    c.steering = static_cast<float>(steering);
    c.headlights = 1;
    c.engaged = engaged;
    signer_.sign(c);
    lcm_.publish(o_.vehicle + AUTODRIVE_CH_COMMAND_SUFFIX, &c);
  }

 private:
  // The advisory is judged fresh by its arrival on this program's clock (wall, or SIM_CLOCK):
  // its stamp is the server's clock, which need not be this one.
  autodrive::behaviour::Advisory advisory() const {
    autodrive::behaviour::Advisory a;
    if (!have_adv_) return a;
    a.fresh = clock_.fresh(adv_at_us_, static_cast<int64_t>(o_.advisory_stale_ms * 1e3));
    a.light_id = adv_.light_id;
    a.light = static_cast<autodrive::behaviour::LightState>(adv_.light_state);
    a.speed_limit_m_s = adv_.speed_limit_m_s;
    return a;
  }

  const Options &o_;
  const autodrive::behaviour::Track &track_;
  autodrive::behaviour::CityRules rules_;
  lcm::LCM &lcm_;
  autodrive::auth::Signer signer_;
  autodrive::clock::Clock clock_;
  autodrive::v2x::Verifier verifier_;
  autodrive::v2v::PeerTable peers_;
  autodrive::v2v::PeerAccount account_;  // per peer: time in the table and holding this car
  autodrive::v2i_advisory_t adv_{};
  int64_t adv_at_us_ = 0;  // the advisory's arrival [us, clock_]
  bool have_adv_ = false, have_s_ = false;
  double s_local_ = 0;
  autodrive::behaviour::CarPose pose_;
  autodrive::behaviour::ObstacleTracker obstacle_;
  int64_t scan_us_ = 0;  // the last scan's stamp [us, car time]
  long lap_ = 0;
  int64_t now_us_ = 0, last_cmd_us_ = 0, last_status_us_ = 0;
  int32_t seq_ = 0;
};

}  // namespace

int main(int argc, char **argv) {
  CLI::App cli{
      "autodrive-city-driver: the smart-city behaviour layer of one car: follows a route of the "
      "map on the runtime's EKF pose, obeys lights (V2I advisory; stale = red), stop signs, "
      "speed limits and curve signs, keeps a gap behind cars ahead (V2V), and sends signed "
      "commands through the runtime's bridge"};
  Options o;
  cli.add_option("--map", o.map, "the map's sidecar JSON (maps/<map>.json)")
      ->required()
      ->check(CLI::ExistingFile);
  cli.add_option("--route", o.route,
                 "a route of the map (e.g. loop_ccw), or lanes:A,B,... (a loop of the map's "
                 "lanes, each starting where the previous ends)")
      ->required();
  cli.add_option("--vehicle", o.vehicle, "the car (channel prefix)")->capture_default_str();
  cli.add_option("--lcm-url", o.lcm_url, "LCM URL (default: LCM's own default)");
  cli.add_option("--key-file", o.key_file,
                 "the car's command key (default: $AUTODRIVE_KEY_DIR/<VEH>.key, else "
                 "~/.config/autodrive/keys/<VEH>.key; tools/keys creates it)");
  cli.add_option("--cruise", o.rules.cruise_m_s, "speed on a free road [m/s]")
      ->check(CLI::Range(0.02, 0.26))
      ->capture_default_str();
  cli.add_option("--curve-speed", o.rules.curve_speed_m_s, "speed after a curve sign [m/s]")
      ->check(CLI::Range(0.02, 0.26))
      ->capture_default_str();
  cli.add_option("--min-gap", o.rules.min_gap_m, "bumper-to-bumper gap behind a car ahead [m]")
      ->check(CLI::Range(0.05, 2.0))
      ->capture_default_str();
  cli.add_option("--advisory-stale-ms", o.advisory_stale_ms,
                 "an advisory older than this [ms, --clock] is stale: every light is red")
      ->check(CLI::Range(50.0, 10000.0))
      ->capture_default_str();
  std::string clock = "wall";
  cli.add_option("--clock", clock,
                 "the clock of staleness: wall (a car) or sim (SIM_CLOCK: HIL, correct at any "
                 "real-time factor; a SIM_CLOCK still for 5 s of wall time stops the car)")
      ->check(CLI::IsMember({"wall", "sim"}))
      ->capture_default_str();
  cli.add_option("--obstacle-margin", o.rules.obstacle_margin_m,
                 "the front stops this far before an obstacle on the path (LIDAR) [m]")
      ->check(CLI::Range(0.03, 1.0))
      ->capture_default_str();
  cli.add_flag("!--no-lidar", o.lidar,
               "do not stop for obstacles: no <VEH>_LIDAR (the car then drives into what is "
               "not on the map)");
  CLI11_PARSE(cli, argc, argv);
  o.clock = *autodrive::clock::clock_mode_named(clock);

  autodrive::behaviour::Track track;
  try {
    const auto city = autodrive::behaviour::load_city_map(o.map);
    track = autodrive::behaviour::track_for(city, o.route);
  } catch (const autodrive::behaviour::Error &e) {
    std::fprintf(stderr, "autodrive-city-driver: %s\n", e.what());
    return 2;
  }
  auto signer = autodrive::auth::load_machine_signer("autodrive-city-driver", o.vehicle, o.key_file,
                                                     "city-driver");
  if (!signer) return 2;
  o.lcm_url = autodrive::instance_lcm_url(o.lcm_url);  // AUTODRIVE_INSTANCE
  auto verifier = autodrive::v2x::Verifier::load("autodrive-city-driver");
  if (!verifier) return 2;
  lcm::LCM lcm(o.lcm_url);
  if (!lcm.good()) {
    std::fprintf(stderr, "autodrive-city-driver: --lcm-url '%s' unusable\n", o.lcm_url.c_str());
    return 2;
  }
  Driver d(o, track, lcm, std::move(*signer), std::move(*verifier));
  autodrive_lcm::subscribe<autodrive::odometry_t, Driver, &Driver::on_pose>(
      lcm, o.vehicle + AUTODRIVE_CH_POSE_MAP_SUFFIX, &d);
  autodrive_lcm::subscribe<autodrive::v2i_advisory_t, Driver, &Driver::on_advisory>(
      lcm, o.vehicle + AUTODRIVE_CH_V2I_SUFFIX, &d);
  autodrive_lcm::subscribe<autodrive::v2v_state_t, Driver, &Driver::on_peer>(lcm, AUTODRIVE_CH_V2V,
                                                                             &d);
  if (o.lidar)
    autodrive_lcm::subscribe<autodrive::lidar_scan_t, Driver, &Driver::on_scan>(
        lcm, o.vehicle + AUTODRIVE_CH_LIDAR_SUFFIX, &d);
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  std::printf("[city-driver] %s on route %s (%.2f m, %s, %zu stops, %zu speed zones)\n",
              o.vehicle.c_str(), track.name.c_str(), track.length_m,
              track.loop ? "loop" : "one way", track.stops.size(), track.zones.size());
  // the rules' figures, one line (tests read their thresholds from it)
  std::printf(
      "[city-driver] rules: min_gap_m=%.3f obstacle_margin_m=%.3f stop_margin_m=%.3f "
      "cruise_m_s=%.3f lidar=%s\n",
      o.rules.min_gap_m, o.rules.obstacle_margin_m, o.rules.stop_margin_m, o.rules.cruise_m_s,
      o.lidar ? "on" : "OFF (obstacles are not seen)");
  for (const auto &st : track.stops)
    std::printf("[city-driver]   stop at s=%.3f m: %s %s\n", st.s_m,
                st.kind == autodrive::behaviour::Stop::Kind::light
                    ? ("light " + std::to_string(st.light_id)).c_str()
                    : "stop sign",
                st.name.c_str());
  std::fflush(stdout);
  while (!g_stop) lcm.handleTimeout(50);
  // Last words: disengaged zero commands (the bridge and the firmware stop the car either way).
  for (int i = 0; i < 5; ++i) {
    d.send(false, 0.0, 0.0);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  const std::string refused = d.refused_summary();
  std::printf("[city-driver] %s: stopped; refused V2X messages: %s\n", o.vehicle.c_str(),
              refused.empty() ? "none" : refused.c_str());
  // per V2V peer accepted (name, certificate serial): seconds of car time in the peer table and
  // holding or slowing this car (tools/bench v2x charges ghosts with it)
  std::printf("[city-driver] %s: peer account: %s\n", o.vehicle.c_str(), d.peer_account().c_str());
  std::fflush(stdout);
  return 0;
}
