// autodrive-marl: one car's intersection traversal on LCM. Subscribes V2V (peers through the
// V2V peer table; a receive-side loss/delay for tests), the car's own EKF pose (<VEH>_POSE_MAP,
// or <VEH>_ODOM placed at --odom-origin) and SIM_CLOCK (--clock sim); builds the observation
// with the MARL core, runs the policy (OpenCV DNN) or the rule-based baseline, passes the
// command through the core's TTC shield and publishes signed <VEH>_COMMAND at the policy's
// control rate, through the runtime's guarded bridge (signature + control lease). Status on
// <VEH>_MISSION at 2 Hz; a JSON summary as the last stdout line at exit.
#include <autodrive/instance.hpp>
#include <autodrive_channels.h>

#include <CLI/CLI.hpp>
#include <autodrive/command_auth.hpp>
#include <autodrive/mission_status_t.hpp>
#include <autodrive/odometry_t.hpp>
#include <autodrive/v2v/peer_account.hpp>
#include <autodrive/v2v/v2v_peers.hpp>
#include <autodrive/v2v_state_t.hpp>
#include <autodrive/v2x.hpp>
#include <autodrive/vehicle_command_t.hpp>
#include <autodrive/vehicle_state_t.hpp>
#include <autodrive_lcm/subscribe.hpp>
#include <lcm/lcm-cpp.hpp>
#include <spdlog/spdlog.h>

#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>

#include <autodrive/core/clock.hpp>
#include <autodrive/marl/core_adapter.hpp>
#include <autodrive/marl/fcfs_baseline.hpp>
#include <autodrive/marl/link_degrade.hpp>
#include <autodrive/marl/policy.hpp>
#include <autodrive/marl/route_map.hpp>

namespace {

volatile std::sig_atomic_t g_stop = 0;
void on_signal(int) {
  g_stop = 1;
}

struct Options {
  std::string vehicle = "NIGEL1", lcm_url = AUTODRIVE_LCM_URL_DEFAULT, mode = "rl";
  std::string policy, map_json, route, clock = "wall", key_file, odom_origin, eval_obs, goal;
  double waypoint_lookahead_m = 0;
  std::string log_level = "info";
  double start_delay_s = 0;
  double v2v_loss = 0, v2v_delay_ms = 0, stale_ms = 200, rate_hz = 20, goal_tolerance_m = 0.15;
  uint64_t seed = 1;
  bool no_shield = false;
  double shield_pose_error_m = 0;
};

class App {
 public:
  App(const Options &o, lcm::LCM &lcm, autodrive::auth::Signer signer,
      autodrive::v2x::Verifier verifier, std::unique_ptr<autodrive::marl::Policy> policy,
      autodrive::marl::Route route, std::unique_ptr<autodrive::marl::FcfsBaseline> baseline,
      std::optional<autodrive::autonomy::Pose2> origin)
      : o_(o),
        lcm_(lcm),
        signer_(std::move(signer)),
        verifier_(std::move(verifier)),
        policy_(std::move(policy)),
        route_(std::move(route)),
        baseline_(std::move(baseline)),
        origin_(origin),
        clock_(*autodrive::clock::clock_mode_named(o.clock)),
        core_(route_, o.waypoint_lookahead_m),
        peers_(o.vehicle, static_cast<int64_t>(o.stale_ms * 1000)),
        link_(o.v2v_loss, static_cast<int64_t>(o.v2v_delay_ms * 1000), o.seed) {
    goal_[0] = route_.points.back().x_m;
    goal_[1] = route_.points.back().y_m;
    if (!o.goal.empty()) std::sscanf(o.goal.c_str(), "%lf,%lf", &goal_[0], &goal_[1]);
    core_.set_goal(goal_[0], goal_[1]);
    core_.set_pose_error_m(o.shield_pose_error_m);
    after_goal_.set_path(route_.path());
    period_us_ =
        static_cast<int64_t>(1e6 * (policy_ ? policy_->spec().control_period_s : 1.0 / o.rate_hz));
  }

  void on_v2v(const lcm::ReceiveBuffer *, const std::string &, const autodrive::v2v_state_t *m) {
    if (m->vehicle == o_.vehicle) return;
    // Only a state signed by the car it names, fresh on this program's clock: no ghost cars.
    // The account keeps which certificate signed it.
    v2x_sender_t sender{};
    if (!verifier_.accept(AUTODRIVE_CH_V2V, *m, AUTODRIVE_CH_V2V_SIGNED_BY, m->vehicle.c_str(),
                          now_us(), &sender))
      return;
    account_.accepted(*m, sender.serial);
    link_.on_receive(*m, now_us());
  }
  void on_pose(const lcm::ReceiveBuffer *, const std::string &, const autodrive::odometry_t *m) {
    autodrive::autonomy::Pose2 p{m->x_m, m->y_m, m->yaw_rad};
    if (origin_) p = autodrive::autonomy::pose_compose(*origin_, p);
    own_ = autodrive::marl::CarState{autodrive::marl::vehicle_id(o_.vehicle), p.x_m, p.y_m,
                                     p.yaw_rad, m->vx_m_s};
    have_pose_ = true;
  }

  // The Nano's applied (rate-limited) steering: the wheels' angle for the shield's lane term.
  void on_state(const lcm::ReceiveBuffer *, const std::string &,
                const autodrive::vehicle_state_t *m) {
    steering_now_ = m->steering_applied;
    have_steering_ = true;
  }

  int64_t now_us() const { return clock_.now_us(); }
  void attach_clock() { clock_.attach(lcm_); }

  // One pass of the loop: deliver due V2V states, command when a control period has passed.
  // Nothing while the clock has no time or a frozen one (no SIM_CLOCK tick for
  // Clock::kFrozenAfterUs of monotonic time): the bridge's command timeout then stops the car.
  void tick() {
    if (clock_.frozen()) return;
    const int64_t now = now_us();
    for (const auto &s : link_.due(now)) peers_.on_state(s, now);
    if (now < static_cast<int64_t>(o_.start_delay_s * 1e6)) return;  // not yet: stays parked
    if (start_us_ < 0) start_us_ = now;
    if (last_cmd_us_ >= 0 && now - last_cmd_us_ < period_us_) return;
    const double dt_s = last_cmd_us_ < 0 ? period_us_ * 1e-6 : (now - last_cmd_us_) * 1e-6;
    last_cmd_us_ = now;
    if (!have_pose_) return;  // nothing to drive on yet: the bridge holds the car still
    const std::vector<autodrive::v2v_state_t> fresh = peers_.fresh(now);
    std::vector<autodrive::marl::CarState> peers;
    for (const auto &s : fresh)
      peers.push_back(
          {autodrive::marl::vehicle_id(s.vehicle), s.x_m, s.y_m, s.yaw_rad, s.speed_m_s});
    const bool at_goal = std::hypot(own_.x_m - goal_[0], own_.y_m - goal_[1]) < o_.goal_tolerance_m;
    if (at_goal && goal_us_ < 0) {
      goal_us_ = now;
      spdlog::info("{} at its goal (route {}) at {:.2f} s", o_.vehicle, route_.name, now * 1e-6);
      publish_status(now);  // at once: the demo times the arrival by it
    }
    double throttle = 0, steering = 0;
    int holding = -1;  // the fresh peer the shield braked for (the account's held time), -1 none
    if (goal_us_ < 0) {
      if (baseline_) {
        const autodrive::marl::DriveCommand c =
            baseline_->step({own_.x_m, own_.y_m, own_.yaw_rad}, own_.speed_m_s, fresh, now, dt_s);
        throttle = c.throttle;
        steering = c.steering;
      } else {
        const std::vector<float> obs = core_.observation(own_, peers, last_steering_);
        const autodrive::marl::PolicyCommand c = policy_->act(obs);
        throttle = c.throttle;
        steering = c.steering;
      }
      if (!o_.no_shield) {
        // The baseline arbitrates the zone by its own rule: its shield is the emergency brake.
        // The lane term for the policy only: the baseline follows its lane itself.
        const double steering_now = baseline_ != nullptr ? std::nan("")
                                    : have_steering_     ? steering_now_
                                                         : last_steering_;
        const autodrive::marl::ShieldResult r =
            core_.shield(own_, throttle, steering, peers, baseline_ != nullptr, steering_now);
        if (r.intervened && r.throttle < throttle) holding = peer_index(fresh, r.peer_id);
        if (r.intervened) {
          ++shield_interventions_;
          lane_steers_ += r.steered ? 1 : 0;
          if (!last_intervened_ && r.peer_id >= 0)
            spdlog::info("shield: brake for NIGEL{}, contact predicted in {:.2f} s", r.peer_id,
                         r.ttc_s);
          else if (!last_intervened_)
            spdlog::info("shield: lane term: steering {:.2f} instead of {:.2f}{}", r.steering,
                         steering, r.throttle != throttle ? ", braking" : "");
        }
        last_intervened_ = r.intervened;
        throttle = r.throttle;
        steering = r.steering;
      }
    }
    if (goal_us_ >= 0) {
      // At the goal: drive on along the route to its end (out of the intersection's way, as
      // in training), braking only for an emergency.
      const autodrive::autonomy::TrackerCommand tc =
          after_goal_.step({own_.x_m, own_.y_m, own_.yaw_rad}, dt_s, own_.speed_m_s);
      const autodrive::marl::ShieldResult r =
          core_.shield(own_, tc.throttle, tc.steering, peers, true);
      if (r.intervened && r.throttle < tc.throttle) holding = peer_index(fresh, r.peer_id);
      throttle = r.throttle;
      steering = r.steering;
    }
    publish(now, throttle, steering, true);
    account_.step(now, fresh, holding);
    last_steering_ = steering;
    ++steps_;
    peers_seen_ = fresh.size();
    if (now - last_status_us_ >= 500000) publish_status(now);
  }

  void publish(int64_t now, double throttle, double steering, bool engaged) {
    autodrive::vehicle_command_t c{};
    c.utime = now;
    c.seq = seq_++;
    c.throttle = static_cast<float>(engaged ? throttle : 0.0);
    c.steering = static_cast<float>(engaged ? steering : 0.0);
    c.engaged = engaged;
    signer_.sign(c);
    lcm_.publish(o_.vehicle + AUTODRIVE_CH_COMMAND_SUFFIX, &c);
  }

  void publish_status(int64_t now) {
    last_status_us_ = now;
    autodrive::mission_status_t m{};
    m.utime = now;
    m.vehicle = o_.vehicle;
    m.state =
        goal_us_ >= 0 ? autodrive::mission_status_t::PARKED : autodrive::mission_status_t::DRIVING;
    const double left = std::hypot(own_.x_m - goal_[0], own_.y_m - goal_[1]);
    m.progress = static_cast<float>(std::clamp(1.0 - left / route_.s_m.back(), 0.0, 1.0));
    m.detail = detail();
    lcm_.publish(o_.vehicle + AUTODRIVE_CH_MISSION_SUFFIX, &m);
  }

  std::string detail() const {
    std::ostringstream s;
    s << "marl " << o_.mode << (o_.no_shield ? " no-shield" : "") << " route " << route_.name
      << " peers " << peers_seen_ << " v2v_received " << link_.received() << " v2v_lost "
      << link_.lost() << " v2v_dropped_stale " << peers_.dropped_stale() << " shield_interventions "
      << shield_interventions_;
    if (baseline_) s << " fcfs " << baseline_->phase();
    return s.str();
  }

  void stop(bool at_exit) {
    if (at_exit) publish(now_us(), 0, 0, false);  // a disengaged stop on the way out
  }

  // The index in fresh of the peer with the shield's id, -1 when none.
  static int peer_index(const std::vector<autodrive::v2v_state_t> &fresh, int peer_id) {
    for (size_t k = 0; k < fresh.size(); ++k)
      if (autodrive::marl::vehicle_id(fresh[k].vehicle) == peer_id) return static_cast<int>(k);
    return -1;
  }

  // The run's figures; peer_account: per V2V peer accepted (name, certificate serial) the
  // seconds of car time in the peer table and those the shield braked for it (the policy's and
  // the baseline's own yielding is not charged to a peer: they weigh every peer at once);
  // v2v_refused: the V2V states the verifier dropped, by reason [count].
  std::string summary_json() const {
    char buf[512];
    std::snprintf(
        buf, sizeof buf,
        "{\"vehicle\": \"%s\", \"mode\": \"%s\", \"shield\": %s, \"route\": \"%s\", "
        "\"steps\": %llu, \"start_s\": %.3f, \"goal_s\": %.3f, \"shield_interventions\": %llu, "
        "\"shield_lane_steers\": %llu, \"v2v_received\": %llu, \"v2v_lost\": %llu, "
        "\"v2v_dropped_stale\": %llu, \"peer_account\": ",
        o_.vehicle.c_str(), o_.mode.c_str(), o_.no_shield ? "false" : "true", route_.name.c_str(),
        static_cast<unsigned long long>(steps_), start_us_ >= 0 ? start_us_ * 1e-6 : -1.0,
        goal_us_ >= 0 ? goal_us_ * 1e-6 : -1.0,
        static_cast<unsigned long long>(shield_interventions_),
        static_cast<unsigned long long>(lane_steers_),
        static_cast<unsigned long long>(link_.received()),
        static_cast<unsigned long long>(link_.lost()),
        static_cast<unsigned long long>(peers_.dropped_stale()));
    return buf + account_.json() + ", \"v2v_refused\": " + verifier_.counts_json() + "}";
  }

 private:
  const Options &o_;
  lcm::LCM &lcm_;
  autodrive::auth::Signer signer_;
  autodrive::v2x::Verifier verifier_;
  std::unique_ptr<autodrive::marl::Policy> policy_;
  autodrive::marl::Route route_;
  std::unique_ptr<autodrive::marl::FcfsBaseline> baseline_;
  std::optional<autodrive::autonomy::Pose2> origin_;
  autodrive::clock::Clock clock_;  // --clock: control period, V2V delay and staleness
  autodrive::marl::Core core_;
  autodrive::autonomy::PurePursuit after_goal_;
  double goal_[2] = {0, 0};
  autodrive::v2v::PeerTable peers_;
  autodrive::v2v::PeerAccount account_;  // per peer: time in the table and braked for
  autodrive::marl::LinkDegrader link_;
  autodrive::marl::CarState own_;
  bool have_pose_ = false, last_intervened_ = false;
  double last_steering_ = 0;
  double steering_now_ = 0;  // <VEH>_STATE's steering_applied, normalised
  bool have_steering_ = false;
  int64_t start_us_ = -1, last_cmd_us_ = -1, last_status_us_ = -1000000000, goal_us_ = -1;
  int64_t period_us_ = 50000;
  int32_t seq_ = 0;
  uint64_t steps_ = 0, shield_interventions_ = 0, lane_steers_ = 0;
  size_t peers_seen_ = 0;
};

// --eval-obs: one observation per CSV line in, the network's raw outputs per line out.
int eval_observations(autodrive::marl::Policy &policy, const std::string &path) {
  std::ifstream f(path);
  if (!f) {
    std::fprintf(stderr, "autodrive-marl: --eval-obs %s: cannot be read\n", path.c_str());
    return 2;
  }
  std::string line;
  int n = 0;
  while (std::getline(f, line)) {
    ++n;
    std::vector<float> obs;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) {
      try {
        obs.push_back(std::stof(cell));
      } catch (const std::exception &) {
        std::fprintf(stderr, "autodrive-marl: --eval-obs %s:%d: '%s' is not a number\n",
                     path.c_str(), n, cell.c_str());
        return 2;
      }
    }
    std::vector<float> out;
    try {
      out = policy.forward(obs);
    } catch (const std::exception &e) {
      std::fprintf(stderr, "autodrive-marl: --eval-obs %s:%d: %s\n", path.c_str(), n, e.what());
      return 2;
    }
    for (size_t i = 0; i < out.size(); ++i) std::printf(i ? ",%.9g" : "%.9g", out[i]);
    std::printf("\n");
  }
  return 0;
}

std::optional<autodrive::autonomy::Pose2> parse_origin(const std::string &text) {
  if (text.empty()) return std::nullopt;
  double x, y, yaw_deg;
  char tail;
  if (std::sscanf(text.c_str(), "%lf,%lf,%lf%c", &x, &y, &yaw_deg, &tail) != 3 ||
      !std::isfinite(x) || !std::isfinite(y) || !std::isfinite(yaw_deg))
    throw std::invalid_argument("--odom-origin '" + text + "': want X,Y,YAW_DEG (finite numbers)");
  return autodrive::autonomy::Pose2{x, y, yaw_deg * M_PI / 180.0};
}

}  // namespace

int main(int argc, char **argv) {
  CLI::App cli{
      "autodrive-marl: one car's intersection traversal (learned policy or first-come-first-"
      "served baseline) on V2V, behind a time-to-collision shield; signed <VEH>_COMMAND out"};
  Options o;
  cli.add_option("--vehicle", o.vehicle, "this car (channel prefix), e.g. NIGEL2")
      ->capture_default_str();
  cli.add_option("--lcm-url", o.lcm_url, "LCM provider")->capture_default_str();
  cli.add_option("--mode", o.mode, "rl (the policy) or baseline (first come, first served)")
      ->check(CLI::IsMember({"rl", "baseline"}))
      ->capture_default_str();
  cli.add_option("--policy", o.policy, "rl: the policy NAME.onnx (NAME.json beside it)");
  cli.add_option("--map-json", o.map_json, "the map's JSON sidecar (routes, the 4-way tile)")
      ->check(CLI::ExistingFile);
  cli.add_option("--route", o.route, "the map's route this car drives");
  cli.add_option("--goal", o.goal,
                 "X,Y: the goal on the route [m] (default: the route's end); at the goal the car "
                 "drives on to the route's end");
  cli.add_option("--waypoint-lookahead-m", o.waypoint_lookahead_m,
                 "rl: the route waypoint's distance ahead in the observation [m], as in training "
                 "(autodrive.learn.marl.env.LOOKAHEAD_M)")
      ->check(CLI::Range(0.01, 5.0));
  cli.add_option("--clock", o.clock, "sim (SIM_CLOCK, HIL) or wall")
      ->check(CLI::IsMember({"sim", "wall"}))
      ->capture_default_str();
  cli.add_option("--odom-origin", o.odom_origin,
                 "X,Y,YAW_DEG: drive on <VEH>_ODOM placed at this map pose [m, m, deg] "
                 "instead of <VEH>_POSE_MAP (HIL without the Eye)");
  cli.add_option("--v2v-loss", o.v2v_loss, "drop each received V2V state with this probability")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  cli.add_option("--v2v-delay-ms", o.v2v_delay_ms, "deliver each V2V state this late [ms]")
      ->check(CLI::Range(0.0, 10000.0))
      ->capture_default_str();
  cli.add_option("--v2v-stale-ms", o.stale_ms, "drop peer states older than this [ms]")
      ->check(CLI::Range(1.0, 10000.0))
      ->capture_default_str();
  cli.add_option(
         "--start-delay-s", o.start_delay_s,
         "send nothing before this clock time [s] (the bridge holds the car; HIL spawn times)")
      ->check(CLI::Range(0.0, 3600.0))
      ->capture_default_str();
  cli.add_option("--seed", o.seed, "seed of the V2V loss")->capture_default_str();
  cli.add_flag("--no-shield", o.no_shield, "send the policy's command unshielded (measuring only)");
  cli.add_option("--shield-pose-error-m", o.shield_pose_error_m,
                 "how far each car's pose may be off [m]: the shield grows every footprint by it "
                 "(default 0: exact poses)")
      ->check(CLI::NonNegativeNumber);
  cli.add_option("--rate-hz", o.rate_hz, "baseline: command rate [Hz]")
      ->check(CLI::Range(1.0, 200.0))
      ->capture_default_str();
  cli.add_option("--goal-tolerance-m", o.goal_tolerance_m, "at the goal within this [m]")
      ->check(CLI::Range(0.01, 1.0))
      ->capture_default_str();
  cli.add_option("--key-file", o.key_file,
                 "the car's command key (default: $AUTODRIVE_KEY_DIR/<VEH>.key, else "
                 "~/.config/autodrive/keys/<VEH>.key; tools/keys creates it)");
  cli.add_option("--eval-obs", o.eval_obs,
                 "rl: print the policy's raw outputs for each CSV line of observations, then exit");
  cli.add_option("--log-level", o.log_level, "trace, debug, info, warn, error")
      ->capture_default_str();
  CLI11_PARSE(cli, argc, argv);
  spdlog::set_level(spdlog::level::from_str(o.log_level));
  spdlog::set_pattern("[marl %n] %^%l%$ %v");

  std::unique_ptr<autodrive::marl::Policy> policy;
  if (o.mode == "rl" || !o.eval_obs.empty()) {
    if (o.policy.empty()) {
      std::fprintf(stderr, "autodrive-marl: --policy: required with --mode rl\n");
      return 2;
    }
    try {
      policy = std::make_unique<autodrive::marl::Policy>(o.policy);
    } catch (const std::exception &e) {
      std::fprintf(stderr, "autodrive-marl: --policy %s\n", e.what());
      return 2;
    }
    if (!o.eval_obs.empty()) return eval_observations(*policy, o.eval_obs);
    if (policy->spec().obs_version != autodrive::marl::obs_version() ||
        policy->spec().obs_dim != autodrive::marl::obs_dim()) {
      std::fprintf(stderr,
                   "autodrive-marl: --policy %s: trained on observation version %d of %d values, "
                   "the MARL core builds version %d of %d\n",
                   o.policy.c_str(), policy->spec().obs_version, policy->spec().obs_dim,
                   autodrive::marl::obs_version(), autodrive::marl::obs_dim());
      return 2;
    }
  }
  if (o.mode == "rl" && o.waypoint_lookahead_m <= 0) {
    std::fprintf(stderr, "autodrive-marl: --waypoint-lookahead-m: required with --mode rl\n");
    return 2;
  }
  double gx, gy;
  char tail;
  if (!o.goal.empty() && (std::sscanf(o.goal.c_str(), "%lf,%lf%c", &gx, &gy, &tail) != 2 ||
                          !std::isfinite(gx) || !std::isfinite(gy))) {
    std::fprintf(stderr, "autodrive-marl: --goal '%s': want X,Y [m] (finite numbers)\n",
                 o.goal.c_str());
    return 2;
  }
  if (o.map_json.empty() || o.route.empty()) {
    std::fprintf(stderr, "autodrive-marl: --map-json and --route are required to drive\n");
    return 2;
  }
  autodrive::marl::Route route;
  std::unique_ptr<autodrive::marl::FcfsBaseline> baseline;
  std::optional<autodrive::autonomy::Pose2> origin;
  try {
    route = autodrive::marl::read_route(o.map_json, o.route);
    if (o.mode == "baseline")
      baseline = std::make_unique<autodrive::marl::FcfsBaseline>(
          o.vehicle, route, autodrive::marl::read_conflict_zone(o.map_json, 0.1));
    origin = parse_origin(o.odom_origin);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "autodrive-marl: %s\n", e.what());
    return 2;
  }
  auto signer =
      autodrive::auth::load_machine_signer("autodrive-marl", o.vehicle, o.key_file, "marl");
  if (!signer) return 2;
  o.lcm_url = autodrive::instance_lcm_url(o.lcm_url);  // AUTODRIVE_INSTANCE
  auto verifier = autodrive::v2x::Verifier::load("autodrive-marl");
  if (!verifier) return 2;
  lcm::LCM lcm(o.lcm_url);
  if (!lcm.good()) {
    std::fprintf(stderr, "autodrive-marl: cannot open LCM at '%s' (multicast route missing?)\n",
                 o.lcm_url.c_str());
    return 2;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  App app(o, lcm, std::move(*signer), std::move(*verifier), std::move(policy), std::move(route),
          std::move(baseline), origin);
  app.attach_clock();
  autodrive_lcm::subscribe<autodrive::v2v_state_t, App, &App::on_v2v>(lcm, AUTODRIVE_CH_V2V, &app)
      ->setQueueCapacity(200);
  const std::string pose_ch =
      o.vehicle + (origin ? AUTODRIVE_CH_ODOM_SUFFIX : AUTODRIVE_CH_POSE_MAP_SUFFIX);
  autodrive_lcm::subscribe<autodrive::odometry_t, App, &App::on_pose>(lcm, pose_ch, &app);
  autodrive_lcm::subscribe<autodrive::vehicle_state_t, App, &App::on_state>(
      lcm, o.vehicle + AUTODRIVE_CH_STATE_SUFFIX, &app);
  spdlog::info("{} mode {}{} on {}: route {}, pose from {}, V2V loss {} delay {} ms", o.vehicle,
               o.mode, o.no_shield ? " (no shield)" : "", o.lcm_url, o.route, pose_ch, o.v2v_loss,
               o.v2v_delay_ms);
  while (!g_stop) {
    lcm.handleTimeout(2);
    app.tick();
  }
  app.stop(true);
  std::printf("%s\n", app.summary_json().c_str());
  std::fflush(stdout);
  return 0;
}
