// Unit tests of autodrive_marl_core (<autodrive/marl_core.h>): the observation layout and the
// time-to-collision shield, with the car's figures from <autodrive_vehicle.h>.
#include <autodrive/marl_core.h>
#include <autodrive_vehicle.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace {

constexpr double kPi = 3.14159265358979323846;

adm_shield_config_t nigel_shield() {
  adm_shield_config_t cfg;
  adm_shield_defaults(&cfg);
  cfg.chassis_length_m = AUTODRIVE_VEHICLE_CHASSIS_SIZE_M_X;
  cfg.chassis_width_m = AUTODRIVE_VEHICLE_CHASSIS_SIZE_M_Y;
  cfg.chassis_offset_m = AUTODRIVE_VEHICLE_CHASSIS_OFFSET_M_X;
  cfg.wheelbase_m = AUTODRIVE_VEHICLE_WHEELBASE_M;
  cfg.steer_limit_rad = AUTODRIVE_VEHICLE_STEER_LIMIT_RAD;
  cfg.top_speed_m_s = AUTODRIVE_VEHICLE_MOTOR_NOLOAD_SPEED_RAD_S * AUTODRIVE_VEHICLE_WHEEL_RADIUS_M;
  return cfg;
}

adm_car_t car(int id, double x, double y, double yaw, double v) {
  return {id, x, y, yaw, v};
}

}  // namespace

TEST(MarlObservation, GoalWaypointAndSpeedInOwnFrame) {
  const adm_car_t self = car(1, 1.0, 2.0, kPi / 2, 0.25);  // facing +y
  const double goal[2] = {1.0, 4.0}, wp[2] = {0.5, 2.0};
  std::vector<float> obs(ADM_OBS_DIM, -9.0f);
  char err[256] = "";
  ASSERT_EQ(
      adm_observation(&self, goal, wp, 0.5, nullptr, 0, obs.data(), ADM_OBS_DIM, err, sizeof err),
      0)
      << err;
  EXPECT_NEAR(obs[0], 2.0 / ADM_POSITION_SCALE_M, 1e-6);  // 2 m straight ahead
  EXPECT_NEAR(obs[1], 0.0, 1e-6);
  EXPECT_NEAR(obs[2], 0.0, 1e-6);
  EXPECT_NEAR(obs[3], 0.5 / ADM_WAYPOINT_SCALE_M, 1e-6);  // 0.5 m to the left
  EXPECT_NEAR(obs[4], 0.25 / ADM_SPEED_SCALE_M_S, 1e-6);
  EXPECT_NEAR(obs[5], 0.5, 1e-6);
  for (int i = ADM_OWN_FEATURES; i < ADM_OBS_DIM; i++)
    EXPECT_EQ(obs[i], 0.0f) << "empty peer slots are zeros, index " << i;
}

TEST(MarlObservation, PeersNearestFirstSkipsSelfAndFarOnes) {
  const adm_car_t self = car(2, 0.0, 0.0, 0.0, 0.0);
  const adm_car_t peers[] = {car(1, 3.0, 0.0, 0.0, 0.1), car(2, 0.0, 0.0, 0.0, 0.0),
                             car(3, 0.0, -1.0, kPi, 0.2), car(4, 9.0, 9.0, 0.0, 0.0),
                             car(5, 1.0, 0.0, kPi / 2, 0.0)};
  const double goal[2] = {1.0, 0.0};
  std::vector<float> obs(ADM_OBS_DIM);
  ASSERT_EQ(adm_observation(&self, goal, goal, 0.0, peers, 5, obs.data(), ADM_OBS_DIM, nullptr, 0),
            0);
  const float *s0 = &obs[ADM_OWN_FEATURES], *s1 = s0 + ADM_PEER_FEATURES,
              *s2 = s1 + ADM_PEER_FEATURES;
  // slot 0: car 3 at 1 m to the right, facing back, tie with car 5 at 1 m broken by... distance
  // equal: the lower id (3) first
  EXPECT_EQ(s0[0], 1.0f);
  EXPECT_NEAR(s0[2], -1.0 / ADM_POSITION_SCALE_M, 1e-6);
  EXPECT_NEAR(s0[3], -1.0, 1e-6);
  EXPECT_NEAR(s0[5], 0.2 / ADM_SPEED_SCALE_M_S, 1e-6);
  EXPECT_NEAR(s1[1], 1.0 / ADM_POSITION_SCALE_M, 1e-6);  // car 5 ahead
  EXPECT_NEAR(s1[4], 1.0, 1e-6);
  EXPECT_NEAR(s2[1], 3.0 / ADM_POSITION_SCALE_M, 1e-6);  // car 1; car 4 is out of range
}

TEST(MarlObservation, RejectsBadInput) {
  const adm_car_t self = car(1, NAN, 0.0, 0.0, 0.0);
  const double goal[2] = {0, 0};
  std::vector<float> obs(ADM_OBS_DIM);
  char err[256] = "";
  EXPECT_EQ(
      adm_observation(&self, goal, goal, 0.0, nullptr, 0, obs.data(), ADM_OBS_DIM, err, sizeof err),
      -1);
  EXPECT_NE(std::string(err).find("not finite"), std::string::npos) << err;
  const adm_car_t ok = car(1, 0, 0, 0, 0);
  EXPECT_EQ(adm_observation(&ok, goal, goal, 0.0, nullptr, 0, obs.data(), 5, err, sizeof err), -1);
  EXPECT_NE(std::string(err).find("obs_len 5"), std::string::npos) << err;
}

TEST(MarlRoute, WaypointAheadAndRemainingLength) {
  const double route[] = {0, 0, 1, 0, 2, 0, 2, 1};  // 3 m, a left corner at (2, 0)
  int hint = -1;
  double wp[2], remaining;
  ASSERT_EQ(adm_route_waypoint(route, 4, 0.9, 0.1, 0.5, &hint, wp, &remaining, nullptr, 0), 0);
  EXPECT_EQ(hint, 1);
  EXPECT_NEAR(wp[0], 1.5, 1e-9);
  EXPECT_NEAR(remaining, 2.0, 1e-9);
  ASSERT_EQ(adm_route_waypoint(route, 4, 1.9, 0.0, 0.5, &hint, wp, &remaining, nullptr, 0), 0);
  EXPECT_EQ(hint, 2);
  EXPECT_NEAR(wp[1], 0.5, 1e-9);  // around the corner
  ASSERT_EQ(adm_route_waypoint(route, 4, 2.0, 0.9, 5.0, &hint, wp, &remaining, nullptr, 0), 0);
  EXPECT_NEAR(wp[1], 1.0, 1e-9);  // clamped at the end
  char err[128];
  EXPECT_EQ(adm_route_waypoint(route, 1, 0, 0, 0.5, &hint, wp, &remaining, err, sizeof err), -1);
}

TEST(MarlShield, BrakesInScriptedHeadOn) {
  // Two cars 1.2 m apart in one lane, facing each other at the top speed: both shields brake
  // (contact within the emergency time for neither yet, but the right-of-way rule makes at
  // least the farther car brake; within emergency_s both do).
  const adm_shield_config_t cfg = nigel_shield();
  const double v = cfg.top_speed_m_s;
  const adm_car_t a = car(1, 0.0, 0.0, 0.0, v);
  const adm_car_t b = car(2, 1.2, 0.0, kPi, v);
  const adm_command_t go = {1.0, 0.0};
  adm_shield_result_t ra, rb;
  char err[256] = "";
  ASSERT_EQ(adm_shield(&cfg, &a, &go, &b, 1, nullptr, &ra, err, sizeof err), 0) << err;
  ASSERT_EQ(adm_shield(&cfg, &b, &go, &a, 1, nullptr, &rb, err, sizeof err), 0) << err;
  EXPECT_TRUE(ra.intervened || rb.intervened) << "neither car brakes head-on";
  const adm_shield_result_t &braked = ra.intervened ? ra : rb;
  EXPECT_EQ(braked.command.throttle, cfg.brake_throttle);
  EXPECT_EQ(braked.command.steering, 0.0);
  EXPECT_LT(braked.ttc_s, cfg.horizon_s);
  // closer in: both brake, whatever the right of way
  const adm_car_t b_near = car(2, 0.5, 0.0, kPi, v);
  ASSERT_EQ(adm_shield(&cfg, &a, &go, &b_near, 1, nullptr, &ra, err, sizeof err), 0);
  ASSERT_EQ(adm_shield(&cfg, &b_near, &go, &a, 1, nullptr, &rb, err, sizeof err), 0);
  EXPECT_TRUE(ra.intervened && rb.intervened);
  EXPECT_EQ(ra.peer_id, 2);
  EXPECT_EQ(rb.peer_id, 1);
  // simulated forward: with the shield, the two cars (kinematic, braking to a stop at once)
  // never touch; without it they do
  for (int shielded = 0; shielded < 2; shielded++) {
    adm_car_t s[2] = {a, b};
    double closest = 1e9;
    for (int k = 0; k < 100; k++) {
      double speed[2];
      for (int i = 0; i < 2; i++) {
        adm_shield_result_t r{};
        ASSERT_EQ(adm_shield(&cfg, &s[i], &go, &s[1 - i], 1, nullptr, &r, nullptr, 0), 0);
        speed[i] = shielded && r.intervened ? 0.0 : v;
      }
      for (int i = 0; i < 2; i++) {
        s[i].speed_m_s = speed[i];
        s[i].x_m += speed[i] * std::cos(s[i].yaw_rad) * 0.05;
      }
      closest = std::fmin(closest, std::fabs(s[1].x_m - s[0].x_m));
    }
    if (shielded)
      EXPECT_GT(closest,
                AUTODRIVE_VEHICLE_CHASSIS_SIZE_M_X + 2 * AUTODRIVE_VEHICLE_CHASSIS_OFFSET_M_X);
    else
      EXPECT_LT(closest, AUTODRIVE_VEHICLE_CHASSIS_SIZE_M_X);
  }
}

TEST(MarlShield, BacksOutOfAStandingDeadlock) {
  // Two standing cars nose to nose (the deadlock a wide turn into the oncoming lane left in the
  // batch): the one that goes first (id 1) still brakes; the other backs up, straight, unless a
  // car stands right behind it.
  const adm_shield_config_t cfg = nigel_shield();
  const adm_command_t go = {1.0, 0.0};
  const adm_car_t a = car(1, 0.0, 0.0, 0.0, 0.0);
  const adm_car_t b = car(2, 0.42, 0.0, kPi, 0.0);
  adm_shield_result_t ra, rb;
  ASSERT_EQ(adm_shield(&cfg, &a, &go, &b, 1, nullptr, &ra, nullptr, 0), 0);
  ASSERT_EQ(adm_shield(&cfg, &b, &go, &a, 1, nullptr, &rb, nullptr, 0), 0);
  EXPECT_TRUE(ra.intervened);
  EXPECT_EQ(ra.command.throttle, cfg.brake_throttle);
  EXPECT_TRUE(rb.intervened);
  EXPECT_EQ(rb.command.throttle, cfg.back_throttle);
  EXPECT_EQ(rb.command.steering, 0.0);
  const adm_car_t peers[2] = {a, car(3, 0.80, 0.0, kPi, 0.0)};  // right behind b
  ASSERT_EQ(adm_shield(&cfg, &b, &go, peers, 2, nullptr, &rb, nullptr, 0), 0);
  EXPECT_TRUE(rb.intervened);
  EXPECT_EQ(rb.command.throttle, cfg.brake_throttle);
}

TEST(MarlShield, LeavesClearAndParallelTrafficAlone) {
  const adm_shield_config_t cfg = nigel_shield();
  const double v = cfg.top_speed_m_s;
  const adm_command_t go = {1.0, 0.0};
  adm_shield_result_t r;
  // opposite lanes 0.28 m apart: passing, not colliding
  const adm_car_t a = car(1, 0.0, -0.14, 0.0, v), b = car(2, 1.0, 0.14, kPi, v);
  ASSERT_EQ(adm_shield(&cfg, &a, &go, &b, 1, nullptr, &r, nullptr, 0), 0);
  EXPECT_FALSE(r.intervened);
  EXPECT_EQ(r.peer_id, -1);
  EXPECT_EQ(r.command.throttle, 1.0);
  // a faster follower behind self: its shield's job, not self's
  const adm_car_t follower = car(3, -0.4, -0.14, 0.0, 2 * v);
  ASSERT_EQ(adm_shield(&cfg, &a, &go, &follower, 1, nullptr, &r, nullptr, 0), 0);
  EXPECT_FALSE(r.intervened);
  ASSERT_EQ(adm_shield(&cfg, &follower, &go, &a, 1, nullptr, &r, nullptr, 0), 0);
  EXPECT_TRUE(r.intervened);
}

TEST(MarlShield, CrossingGivesWayToTheNearerCarOnly) {
  const adm_shield_config_t cfg = nigel_shield();
  const double v = cfg.top_speed_m_s;
  const adm_command_t go = {1.0, 0.0};
  // a from the west to the east, b from the south to the north, b nearer the crossing
  const adm_car_t a = car(1, -0.9, 0.0, 0.0, v), b = car(2, 0.0, -0.6, kPi / 2, v);
  adm_shield_result_t ra, rb;
  ASSERT_EQ(adm_shield(&cfg, &a, &go, &b, 1, nullptr, &ra, nullptr, 0), 0);
  ASSERT_EQ(adm_shield(&cfg, &b, &go, &a, 1, nullptr, &rb, nullptr, 0), 0);
  EXPECT_TRUE(ra.intervened);
  EXPECT_FALSE(rb.intervened);
}

TEST(MarlShield, RejectsBadConfig) {
  adm_shield_config_t cfg;
  adm_shield_defaults(&cfg);  // the car's figures are still 0
  const adm_car_t a = car(1, 0, 0, 0, 0);
  const adm_command_t go = {1.0, 0.0};
  adm_shield_result_t r;
  char err[256] = "";
  EXPECT_EQ(adm_shield(&cfg, &a, &go, nullptr, 0, nullptr, &r, err, sizeof err), -1);
  EXPECT_NE(std::string(err).find("config"), std::string::npos) << err;
}

namespace {

// A lane along +x to (0, 0), a right turn of radius 0.46 m to (0.46, -0.46), then along -y
// (Intersection School's right turns are of this size); 5 cm between points on the straights.
std::vector<double> right_turn_lane() {
  std::vector<double> xy;
  for (int i = 0; i < 40; i++) xy.insert(xy.end(), {-2.0 + 0.05 * i, 0.0});
  const double r = 0.46;
  for (int k = 0; k <= 12; k++) {
    const double a = k * kPi / 24;
    xy.insert(xy.end(), {r * std::sin(a), -r + r * std::cos(a)});
  }
  for (int i = 1; i < 40; i++) xy.insert(xy.end(), {r, -r - 0.05 * i});
  return xy;
}

// The bare chassis box of a car at c touches a pole of radius 8 mm at (px, py).
bool chassis_touches(const adm_shield_config_t &cfg, const adm_car_t &c, double px, double py) {
  const double dx = px - c.x_m, dy = py - c.y_m;
  const double along = std::cos(c.yaw_rad) * dx + std::sin(c.yaw_rad) * dy - cfg.chassis_offset_m;
  const double side = -std::sin(c.yaw_rad) * dx + std::cos(c.yaw_rad) * dy;
  return std::fabs(along) < 0.5 * cfg.chassis_length_m + 0.008 &&
         std::fabs(side) < 0.5 * cfg.chassis_width_m + 0.008;
}

struct WeaveRun {
  bool touched_pole = false;
  bool lane_steered = false;
  double end_y_m = 0;  // where the car was at the end (the lane ends at y = -2.41 m)
};

// A car driving the lane alone with a bang-bang policy (full lock towards a point 0.8 m ahead on
// the lane, a 0.05 rad dead band: it turns in early and weaves, like the batch's discrete
// policy), its steering servo slewing at the car's rate, every 0.1 s a command through the
// shield (with_lane: the lane term on, the measured wheel angle as steering_now). A traffic
// light's pole stands 0.24 m right of the lane where the turn starts, as on the map.
WeaveRun weave_through_right_turn(bool with_lane) {
  adm_shield_config_t cfg = nigel_shield();
  cfg.steer_rate_rad_s = AUTODRIVE_VEHICLE_STEER_RATE_RAD_S;
  const std::vector<double> xy = right_turn_lane();
  const int n = static_cast<int>(xy.size() / 2);
  const double pole_x = 0.0, pole_y = -0.24, v = cfg.top_speed_m_s, dt = 0.01;
  adm_car_t c = car(1, -1.0, 0.0, 0.0, v);
  double wheel_rad = 0.0;
  adm_command_t cmd = {1.0, 0.0};
  int hint = -1;
  WeaveRun out;
  for (int k = 0; k < 1500 && c.y_m > -1.2; k++) {
    if (k % 10 == 0) {
      double aim[2], remaining;
      EXPECT_EQ(
          adm_route_waypoint(xy.data(), n, c.x_m, c.y_m, 0.8, &hint, aim, &remaining, nullptr, 0),
          0);
      const double b =
          std::remainder(std::atan2(aim[1] - c.y_m, aim[0] - c.x_m) - c.yaw_rad, 2 * kPi);
      const adm_command_t intended = {1.0, std::fabs(b) < 0.05 ? 0.0 : (b > 0 ? 1.0 : -1.0)};
      cmd = intended;
      if (with_lane) {
        const adm_lane_t lane = {xy.data(), n, hint, 0.14, wheel_rad / cfg.steer_limit_rad};
        adm_shield_result_t r{};
        EXPECT_EQ(adm_shield(&cfg, &c, &intended, nullptr, 0, &lane, &r, nullptr, 0), 0);
        out.lane_steered |= r.steered != 0;
        cmd = r.command;
      }
    }
    const double step = cfg.steer_rate_rad_s * dt;
    wheel_rad += std::fmax(-step, std::fmin(step, cmd.steering * cfg.steer_limit_rad - wheel_rad));
    const double speed = cmd.throttle > 0 ? v : 0.0;
    c.yaw_rad += speed * std::tan(wheel_rad) / cfg.wheelbase_m * dt;
    c.x_m += speed * std::cos(c.yaw_rad) * dt;
    c.y_m += speed * std::sin(c.yaw_rad) * dt;
    out.touched_pole |= chassis_touches(cfg, c, pole_x, pole_y);
  }
  out.end_y_m = c.y_m;
  return out;
}

}  // namespace

TEST(MarlShield, LaneTermHoldsAWeavingCarOffThePole) {
  // The batch's 13 collisions: a car alone, weaving into the traffic light's pole at the start
  // of a right turn. The car-to-car shield cannot see it; the lane term steers it back.
  const WeaveRun bare = weave_through_right_turn(false);
  EXPECT_TRUE(bare.touched_pole) << "the scripted weave should hit the pole without the lane term";
  const WeaveRun held = weave_through_right_turn(true);
  EXPECT_TRUE(held.lane_steered);
  EXPECT_FALSE(held.touched_pole);
  EXPECT_LT(held.end_y_m, -1.2) << "the lane term must not stop the car";
}

TEST(MarlShield, LaneTermLeavesALaneFollowingCarAlone) {
  // Straight on in the middle of the lane, or a gentle correction: nothing to do.
  adm_shield_config_t cfg = nigel_shield();
  cfg.steer_rate_rad_s = AUTODRIVE_VEHICLE_STEER_RATE_RAD_S;
  const std::vector<double> xy = right_turn_lane();
  const adm_lane_t lane = {xy.data(), static_cast<int>(xy.size() / 2), -1, 0.14, 0.0};
  const adm_car_t c = car(1, -1.0, 0.02, 0.0, cfg.top_speed_m_s);
  for (double steering : {0.0, -0.2, 0.2}) {
    const adm_command_t go = {1.0, steering};
    adm_shield_result_t r{};
    ASSERT_EQ(adm_shield(&cfg, &c, &go, nullptr, 0, &lane, &r, nullptr, 0), 0);
    EXPECT_FALSE(r.intervened) << "steering " << steering;
    EXPECT_EQ(r.command.steering, steering);
  }
  // already turning left (17 deg, the wheels at full left lock): holding full left leaves the
  // lane, so the lane term steers back (the follower's steering, right of the command)
  const adm_car_t turning = car(1, -1.0, 0.05, 0.3, cfg.top_speed_m_s);
  adm_lane_t lane_locked = lane;
  lane_locked.steering_now = 1.0;
  const adm_command_t hard_left = {1.0, 1.0};
  adm_shield_result_t r{};
  ASSERT_EQ(adm_shield(&cfg, &turning, &hard_left, nullptr, 0, &lane_locked, &r, nullptr, 0), 0);
  EXPECT_TRUE(r.steered);
  EXPECT_TRUE(r.intervened);
  EXPECT_LT(r.command.steering, 0.0);
  // a bad lane is refused, naming it
  const adm_lane_t bad = {xy.data(), 1, -1, 0.14, 0.0};
  char err[256] = "";
  EXPECT_EQ(adm_shield(&cfg, &turning, &hard_left, nullptr, 0, &bad, &r, err, sizeof err), -1);
  EXPECT_NE(std::string(err).find("lane"), std::string::npos) << err;
}

TEST(MarlShield, BacksOutOfTheTurningPathOfAStandingFirstCar) {
  // Car 1 stands facing +x; car 2 (drifted) stands nose-down across car 1's left turn, clear of
  // car 1's straight path, and waits for car 1: car 1 goes first, so car 2 backs up (batch seed
  // 1000000106, a ring of standing cars where the back-out rule looked at straight paths only).
  const adm_shield_config_t cfg = nigel_shield();
  const adm_command_t go = {1.0, 0.0};
  const adm_car_t a = car(1, 0.0, 0.0, 0.0, 0.0);
  const adm_car_t b = car(2, 0.25, 0.35, -kPi / 2, 0.0);
  adm_shield_result_t rb;
  ASSERT_EQ(adm_shield(&cfg, &b, &go, &a, 1, nullptr, &rb, nullptr, 0), 0);
  EXPECT_TRUE(rb.intervened);
  EXPECT_EQ(rb.command.throttle, cfg.back_throttle);
  EXPECT_EQ(rb.command.steering, 0.0);
  // farther up, out of every path of car 1 within the emergency time: it only waits
  const adm_car_t b_far = car(2, 0.25, 0.6, -kPi / 2, 0.0);
  ASSERT_EQ(adm_shield(&cfg, &b_far, &go, &a, 1, nullptr, &rb, nullptr, 0), 0);
  EXPECT_TRUE(rb.intervened);
  EXPECT_EQ(rb.command.throttle, cfg.brake_throttle);
}

TEST(MarlShield, PoseErrorGrowsTheFootprints) {
  // Two cars passing in opposite lanes 0.28 m apart: clear with exact poses; with each pose
  // possibly 0.1 m off (HIL on dead reckoning) they might touch, so the one giving way brakes.
  adm_shield_config_t cfg = nigel_shield();
  const double v = cfg.top_speed_m_s;
  const adm_command_t go = {1.0, 0.0};
  const adm_car_t a = car(1, 0.0, -0.14, 0.0, v), b = car(2, 1.0, 0.14, kPi, v);
  adm_shield_result_t ra, rb;
  cfg.pose_error_m = 0.1;
  ASSERT_EQ(adm_shield(&cfg, &a, &go, &b, 1, nullptr, &ra, nullptr, 0), 0);
  ASSERT_EQ(adm_shield(&cfg, &b, &go, &a, 1, nullptr, &rb, nullptr, 0), 0);
  EXPECT_TRUE(ra.intervened || rb.intervened);
  cfg.pose_error_m = -0.1;
  char err[256] = "";
  EXPECT_EQ(adm_shield(&cfg, &a, &go, &b, 1, nullptr, &ra, err, sizeof err), -1);
  EXPECT_NE(std::string(err).find("pose error"), std::string::npos) << err;
}

TEST(MarlShield, KeepsBackingOutOnceRollingBack) {
  // The nose-to-nose pair of BacksOutOfAStandingDeadlock, car 2 already rolling back at 3 cm/s:
  // it keeps backing (it used to count as moving and brake, so it backed 0.2 s in every 0.4 s;
  // batch seed 1000000088). Driving forward, it brakes as before.
  const adm_shield_config_t cfg = nigel_shield();
  const adm_command_t go = {1.0, 0.0};
  const adm_car_t a = car(1, 0.0, 0.0, 0.0, 0.0);
  adm_shield_result_t rb;
  const adm_car_t rolling_back = car(2, 0.42, 0.0, kPi, -0.03);
  ASSERT_EQ(adm_shield(&cfg, &rolling_back, &go, &a, 1, nullptr, &rb, nullptr, 0), 0);
  EXPECT_EQ(rb.command.throttle, cfg.back_throttle);
  const adm_car_t rolling_on = car(2, 0.42, 0.0, kPi, 0.03);
  ASSERT_EQ(adm_shield(&cfg, &rolling_on, &go, &a, 1, nullptr, &rb, nullptr, 0), 0);
  EXPECT_EQ(rb.command.throttle, cfg.brake_throttle);
}

TEST(MarlShield, BacksOutPastACornerItGrazes) {
  // Batch seed 1000000088: car 2, turning left, stands with its rear corner at car 1's front
  // corner. Its way back slides past that corner at a near constant distance (0.2 mm closer at
  // worst): that is not closing, so it backs out instead of both standing for ever.
  const adm_shield_config_t cfg = nigel_shield();
  const adm_command_t go = {1.0, 0.0};
  const adm_car_t a = car(1, -0.392, -0.149, -1.0 * kPi / 180.0, 0.0);
  const adm_car_t b = car(2, -0.159, -0.011, 150.0 * kPi / 180.0, 0.0);
  adm_shield_result_t ra, rb;
  ASSERT_EQ(adm_shield(&cfg, &b, &go, &a, 1, nullptr, &rb, nullptr, 0), 0);
  EXPECT_EQ(rb.command.throttle, cfg.back_throttle);
  ASSERT_EQ(adm_shield(&cfg, &a, &go, &b, 1, nullptr, &ra, nullptr, 0), 0);
  EXPECT_EQ(ra.command.throttle, cfg.brake_throttle);  // car 2 is still in its way
}

TEST(MarlShield, StandingCarLetsAStandingFirstCarStart) {
  // Car 1 stands facing +x, car 2 stands south-east of it facing +y: their straight paths cross
  // 0.45 m ahead of car 1. Car 1 goes first (both stand, lower id); car 2 no longer starts into
  // its way just because car 1 stands now (batch seed 1000000187: a car that had backed out of a
  // first car's way drove in again as soon as it was out).
  const adm_shield_config_t cfg = nigel_shield();
  const adm_command_t go = {1.0, 0.0};
  const adm_car_t a = car(1, 0.0, 0.0, 0.0, 0.0);
  const adm_car_t b = car(2, 0.45, -0.45, kPi / 2, 0.0);
  adm_shield_result_t ra, rb;
  ASSERT_EQ(adm_shield(&cfg, &a, &go, &b, 1, nullptr, &ra, nullptr, 0), 0);
  EXPECT_FALSE(ra.intervened);
  ASSERT_EQ(adm_shield(&cfg, &b, &go, &a, 1, nullptr, &rb, nullptr, 0), 0);
  EXPECT_TRUE(rb.intervened);
  EXPECT_EQ(rb.command.throttle, cfg.brake_throttle);
  EXPECT_EQ(rb.peer_id, 1);
  // car 1 behind car 2's start line, facing away: nothing to wait for
  const adm_car_t a_away = car(1, 0.0, 0.0, kPi, 0.0);
  ASSERT_EQ(adm_shield(&cfg, &b, &go, &a_away, 1, nullptr, &rb, nullptr, 0), 0);
  EXPECT_FALSE(rb.intervened);
}
