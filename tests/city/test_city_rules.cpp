// The behaviour layer's map reading and rules of the road on Tiny Town's real sidecar JSON.
#include <gtest/gtest.h>

#include <fstream>

#include <autodrive/behaviour/city_map.hpp>
#include <autodrive/behaviour/city_rules.hpp>
#include <autodrive/behaviour/obstacle.hpp>

using namespace autodrive::behaviour;

namespace {

const std::string kMap = std::string(AUTODRIVE_ROOT) + "/maps/tiny_town.json";

const CityMap &city() {
  static const CityMap m = load_city_map(kMap);
  return m;
}

const Stop &stop_of(const Track &t, Stop::Kind kind) {
  for (const Stop &s : t.stops)
    if (s.kind == kind) return s;
  throw std::runtime_error("no such stop");
}

RulesInput at(double s_m, double v, int64_t t_us, Advisory a = {}) {
  RulesInput in;
  in.s_m = s_m;
  in.speed_m_s = v;
  in.t_us = t_us;
  in.advisory = a;
  return in;
}

Advisory fresh(int light, LightState st) {
  Advisory a;
  a.fresh = true;
  a.light_id = light;
  a.light = st;
  return a;
}

}  // namespace

TEST(CityMap, RouteCityEastHasLight3AndTheStopSign) {
  const Track t = track_for(city(), "city_east");
  EXPECT_TRUE(t.loop);
  EXPECT_NEAR(t.length_m, 18.49, 0.05);
  ASSERT_EQ(t.stops.size(), 2u);
  EXPECT_EQ(stop_of(t, Stop::Kind::light).light_id, 3);
  EXPECT_EQ(stop_of(t, Stop::Kind::light).name, "x_stop_s");
  EXPECT_LT(stop_of(t, Stop::Kind::light).s_m, stop_of(t, Stop::Kind::stop_sign).s_m);
  // The stop line lies on the track: its point there is the map's stop line centre.
  const TrackPoint p = point_at(t, stop_of(t, Stop::Kind::light).s_m);
  EXPECT_NEAR(p.x_m, 0.14, 0.01);
  EXPECT_NEAR(p.y_m, -1.25, 0.01);
  const Track ccw = track_for(city(), "loop_ccw");
  EXPECT_TRUE(ccw.stops.empty());   // round the town: no light, no stop sign
  EXPECT_EQ(ccw.zones.size(), 2u);  // the speed limit and the curve sign
}

TEST(CityMap, ProjectionFindsProgressAndSide) {
  const Track t = track_for(city(), "city_east");
  const TrackPoint p = point_at(t, 5.0);
  const Projection q = project(t, p.x_m + 0.05 * -std::sin(p.heading_rad),
                               p.y_m + 0.05 * std::cos(p.heading_rad), 4.9);
  EXPECT_NEAR(q.s_m, 5.0, 0.01);
  EXPECT_NEAR(q.lateral_m, 0.05, 0.005);  // left of the track
}

TEST(CityMap, BadInputNamesWhatIsWrong) {
  EXPECT_THROW(load_city_map("/nonexistent/map.json"), Error);
  try {
    track_for(city(), "no_such_route");
    FAIL();
  } catch (const Error &e) {
    EXPECT_NE(std::string(e.what()).find("city_east"), std::string::npos) << e.what();
  }
  try {
    track_for(city(), "lanes:x_s_n,e1_s_n");
    FAIL();
  } catch (const Error &e) {
    EXPECT_NE(std::string(e.what()).find("does not start where"), std::string::npos) << e.what();
  }
  const std::string bad = ::testing::TempDir() + "/bad_map.json";
  std::ofstream(bad) << R"({"name": "x", "lanes": [{"name": "a"}]})";
  try {
    load_city_map(bad);
    FAIL();
  } catch (const Error &e) {
    EXPECT_NE(std::string(e.what()).find("lane a: missing key 'centre_line'"), std::string::npos)
        << e.what();
  }
}

TEST(CityRules, StaleAdvisoryMeansRedEvenWhenTheLightIsGreen) {
  const Track t = track_for(city(), "city_east");
  RulesConfig cfg;
  CityRules r(t, cfg);
  const double line = stop_of(t, Stop::Kind::light).s_m;
  const double at_target = line - cfg.stop_margin_m - cfg.front_m;  // base_link where it stops
  Advisory stale = fresh(3, LightState::green);
  stale.fresh = false;
  auto out = r.step(at(at_target, 0.0, 0, stale));
  EXPECT_EQ(out.speed_m_s, 0.0);
  EXPECT_NE(out.reason.find("stale advisory: red light 3"), std::string::npos) << out.reason;
  // Fresh and green: go.
  out = r.step(at(at_target, 0.0, 0, fresh(3, LightState::green)));
  EXPECT_DOUBLE_EQ(out.speed_m_s, cfg.cruise_m_s);
  // Fresh, but about another light: light 3 is red for this car.
  out = r.step(at(at_target, 0.0, 0, fresh(1, LightState::green)));
  EXPECT_EQ(out.speed_m_s, 0.0);
  // Red: the allowed speed falls to 0 at the stop target, and is positive before it.
  const auto near = r.step(at(at_target - 0.02, 0.15, 0, fresh(3, LightState::red)));
  EXPECT_GT(near.speed_m_s, 0.1);  // sqrt(2 * 0.3 * 0.02) = 0.155 m/s
  EXPECT_LT(near.speed_m_s, cfg.cruise_m_s);
  EXPECT_EQ(near.reason, "red light 3 at x_stop_s");
  EXPECT_EQ(r.step(at(at_target + 0.01, 0.0, 0, fresh(3, LightState::red))).speed_m_s, 0.0);
}

TEST(CityRules, YellowStopsWhenItComfortablyCanElseGoesOn) {
  const Track t = track_for(city(), "city_east");
  RulesConfig cfg;
  const double line = stop_of(t, Stop::Kind::light).s_m;
  const double target = line - cfg.stop_margin_m - cfg.front_m;
  {
    CityRules r(t, cfg);  // 4 cm before the target at 0.1 m/s: 1.7 cm needed, so stop
    const auto out = r.step(at(target - 0.04, 0.1, 0, fresh(3, LightState::yellow)));
    EXPECT_LT(out.speed_m_s, cfg.cruise_m_s);
    EXPECT_NE(out.reason.find("yellow"), std::string::npos);
    EXPECT_EQ(r.step(at(target, 0.0, 1000, fresh(3, LightState::yellow))).speed_m_s, 0.0);
  }
  {
    CityRules r(t, cfg);  // 2 cm before the target at 0.2 m/s: it cannot stop there; go on
    const auto out = r.step(at(target - 0.02, 0.2, 0, fresh(3, LightState::yellow)));
    EXPECT_DOUBLE_EQ(out.speed_m_s, cfg.cruise_m_s);
    // decided once: still going when it has slowed a little
    EXPECT_DOUBLE_EQ(r.step(at(target, 0.15, 1000, fresh(3, LightState::yellow))).speed_m_s,
                     cfg.cruise_m_s);
  }
}

// A red (or a stale advisory) that comes when the car can no longer stop before the line: it
// goes on instead of standing over the line (seed 1's 4.45 cm overshoot); one that comes in time
// stops it, however hard.
TEST(CityRules, ARedTooLateToStopBeforeTheLineIsDrivenThrough) {
  const Track t = track_for(city(), "city_east");
  RulesConfig cfg;
  const double line = stop_of(t, Stop::Kind::light).s_m;
  const double front_at_line = line - cfg.front_m;  // base_link when the front is at the line
  Advisory stale = fresh(3, LightState::green);
  stale.fresh = false;
  for (const Advisory &red : {fresh(3, LightState::red), stale}) {
    {
      // The front 1 cm before the line at cruise: a hard stop needs 0.2 * 0.1 + 0.02 = 4 cm.
      CityRules r(t, cfg);
      const auto out = r.step(at(front_at_line - 0.01, cfg.cruise_m_s, 0, red));
      EXPECT_DOUBLE_EQ(out.speed_m_s, cfg.cruise_m_s) << out.reason;
      // decided once: still going when the front is over the line
      EXPECT_DOUBLE_EQ(r.step(at(front_at_line + 0.01, 0.19, 20000, red)).speed_m_s,
                       cfg.cruise_m_s);
    }
    {
      // The front 2 cm past the line (a green it went on): the light is behind it.
      CityRules r(t, cfg);
      EXPECT_DOUBLE_EQ(r.step(at(front_at_line + 0.02, cfg.cruise_m_s, 0, red)).speed_m_s,
                       cfg.cruise_m_s);
    }
    {
      // 6 cm before the line: it can stop before it, so it brakes (2 cm to its target)...
      CityRules r(t, cfg);
      const auto out = r.step(at(front_at_line - 0.06, cfg.cruise_m_s, 0, red));
      EXPECT_LT(out.speed_m_s, 0.12) << out.reason;  // sqrt(2 * 0.3 * 0.02) = 0.11 m/s
      EXPECT_NE(out.reason.find("red light 3"), std::string::npos) << out.reason;
      // ... and stays stopped on this pass, also standing a little over its target
      EXPECT_EQ(r.step(at(front_at_line - 0.02, 0.0, 500000, red)).speed_m_s, 0.0);
    }
  }
  {
    // A yellow it went on turns red 5 cm before the line at cruise: a hard stop still fits.
    CityRules r(t, cfg);
    EXPECT_DOUBLE_EQ(
        r.step(at(front_at_line - 0.06, cfg.cruise_m_s, 0, fresh(3, LightState::yellow))).speed_m_s,
        cfg.cruise_m_s);
    EXPECT_LT(r.step(at(front_at_line - 0.05, cfg.cruise_m_s, 20000, fresh(3, LightState::red)))
                  .speed_m_s,
              0.08);  // sqrt(2 * 0.3 * 0.01) = 0.077 m/s
  }
}

TEST(CityRules, StopSignNeedsAFullStopOfOneSecond) {
  const Track t = track_for(city(), "city_east");
  RulesConfig cfg;
  CityRules r(t, cfg);
  const double target = stop_of(t, Stop::Kind::stop_sign).s_m - cfg.stop_margin_m - cfg.front_m;
  const Advisory g = fresh(-1, LightState::off);
  EXPECT_EQ(r.step(at(target, 0.0, 0, g)).speed_m_s, 0.0);
  EXPECT_EQ(r.step(at(target, 0.0, 900000, g)).speed_m_s, 0.0);    // 0.9 s: not yet
  EXPECT_EQ(r.step(at(target, 0.05, 1000000, g)).speed_m_s, 0.0);  // rolled: starts again
  EXPECT_EQ(r.step(at(target, 0.0, 1100000, g)).speed_m_s, 0.0);
  EXPECT_EQ(r.step(at(target, 0.0, 2000000, g)).speed_m_s, 0.0);                    // 0.9 s since
  EXPECT_DOUBLE_EQ(r.step(at(target, 0.0, 2400000, g)).speed_m_s, cfg.cruise_m_s);  // 1.3 s
  EXPECT_EQ(r.stop_signs_served(), 1u);
}

TEST(CityRules, KeepsTheGapBehindACarAhead) {
  const Track t = track_for(city(), "loop_ccw");
  RulesConfig cfg;
  CityRules r(t, cfg);
  RulesInput in = at(1.0, 0.2, 0);
  in.peers_ahead_m = {cfg.front_m + cfg.rear_m + cfg.min_gap_m};  // exactly the gap: stand
  EXPECT_EQ(r.step(in).speed_m_s, 0.0);
  in.peers_ahead_m = {1.0};
  EXPECT_DOUBLE_EQ(r.step(in).speed_m_s, cfg.cruise_m_s);
  in.peers_ahead_m = {0.4};  // 1 cm of room beyond the gap
  const auto out = r.step(in);
  EXPECT_LT(out.speed_m_s, cfg.cruise_m_s);
  EXPECT_EQ(out.reason, "car ahead");
  EXPECT_EQ(out.peer_index, 0);
}

// The peer charged with holding the car is the one whose gap binds, and none when another
// limit binds (the driver's per-peer account rests on this).
TEST(CityRules, NamesThePeerWhoseGapLimitsTheSpeed) {
  const Track t = track_for(city(), "loop_ccw");
  RulesConfig cfg;
  CityRules r(t, cfg);
  RulesInput in = at(1.0, 0.2, 0);
  const double stand_m = cfg.front_m + cfg.rear_m + cfg.min_gap_m;  // bumper gap = min_gap_m
  in.peers_ahead_m = {1.0, stand_m, 0.4};
  EXPECT_EQ(r.step(in).peer_index, 1);
  in.peers_ahead_m = {1.0, 1.1};  // both far: cruise, no peer to blame
  EXPECT_EQ(r.step(in).peer_index, -1);
  in.peers_ahead_m = {0.4};
  in.scan_fresh = false;  // no LIDAR scan holds the car at 0 m/s, below the peer's limit
  const auto out = r.step(in);
  EXPECT_EQ(out.speed_m_s, 0.0);
  EXPECT_EQ(out.peer_index, -1);
}

namespace {

// A 360-ray scan of the car at `car` with returns only from the map points `hits` (each on the
// ray nearest its bearing and that ray's neighbour, as a small box gives).
Scan scan_of(const CarPose &car, const std::vector<std::pair<double, double>> &hits,
             const ObstacleConfig &cfg) {
  Scan s;
  s.angle_min_rad = -M_PI;
  s.angle_increment_rad = 2 * M_PI / 360;
  s.range_min_m = 0.15;
  s.range_max_m = 12.0;
  s.ranges_m.assign(360, std::numeric_limits<float>::infinity());
  const double c = std::cos(car.yaw_rad), sn = std::sin(car.yaw_rad);
  const double lx = car.x_m + c * cfg.lidar_x_m - sn * cfg.lidar_y_m;
  const double ly = car.y_m + sn * cfg.lidar_x_m + c * cfg.lidar_y_m;
  for (const auto &[x, y] : hits) {
    const double bearing = std::remainder(std::atan2(y - ly, x - lx) - car.yaw_rad, 2 * M_PI);
    const auto i =
        static_cast<size_t>(std::lround((bearing - s.angle_min_rad) / s.angle_increment_rad)) % 360;
    s.ranges_m[i] = s.ranges_m[(i + 1) % 360] = static_cast<float>(std::hypot(x - lx, y - ly));
  }
  return s;
}

// The map point `along_m` ahead of the car on its track, `left_m` to the left of it.
std::pair<double, double> on_track(const Track &t, double s_m, double left_m) {
  const TrackPoint p = point_at(t, s_m);
  return {p.x_m - left_m * std::sin(p.heading_rad), p.y_m + left_m * std::cos(p.heading_rad)};
}

// The car on the track's centre line at progress s_m, heading along it.
CarPose car_at(const Track &t, double s_m) {
  const TrackPoint p = point_at(t, s_m);
  return {p.x_m, p.y_m, p.heading_rad, s_m};
}

}  // namespace

TEST(Obstacle, AReturnOnThePathIsFoundAlongTheTrack) {
  const Track t = track_for(city(), "city_east");
  const ObstacleConfig cfg;
  const double front_m = RulesConfig{}.front_m;
  const CarPose car = car_at(t, 1.0);
  // a box 0.6 m ahead of base_link on the centre line
  EXPECT_NEAR(obstacle_ahead_m(t, car, scan_of(car, {on_track(t, 1.6, 0.0)}, cfg), cfg, front_m),
              0.6, 0.02);
  // the same beside the path (the other lane's centre, 0.28 m to the left): clear
  EXPECT_LT(obstacle_ahead_m(t, car, scan_of(car, {on_track(t, 1.6, 0.28)}, cfg), cfg, front_m),
            0.0);
  // just inside the corridor: on the path
  EXPECT_GT(
      obstacle_ahead_m(t, car, scan_of(car, {on_track(t, 1.6, cfg.corridor_half_m - 0.01)}, cfg),
                       cfg, front_m),
      0.0);
  // beyond the horizon: later
  EXPECT_LT(obstacle_ahead_m(t, car, scan_of(car, {on_track(t, 3.0, 0.0)}, cfg), cfg, front_m),
            0.0);
  // a single stray return is noise
  Scan one = scan_of(car, {on_track(t, 1.6, 0.0)}, cfg);
  int returns = 0;
  for (auto &r : one.ranges_m)
    if (std::isfinite(r) && ++returns > 1) r = std::numeric_limits<float>::infinity();
  EXPECT_LT(obstacle_ahead_m(t, car, one, cfg, front_m), 0.0);
}

TEST(CityRules, StopsBeforeAnObstacleWaitsAndGoesOnWhenItIsGone) {
  const Track t = track_for(city(), "city_east");
  RulesConfig cfg;
  CityRules r(t, cfg);
  RulesInput in = at(1.0, 0.2, 0);
  in.obstacle_ahead_m = cfg.front_m + cfg.obstacle_margin_m;  // the front at the margin: stand
  auto out = r.step(in);
  EXPECT_EQ(out.speed_m_s, 0.0);
  EXPECT_EQ(out.reason, "obstacle ahead (LIDAR)");
  in.obstacle_ahead_m = cfg.front_m + cfg.obstacle_margin_m + 0.05;  // 5 cm of room: slow
  EXPECT_GT(r.step(in).speed_m_s, 0.0);
  EXPECT_LT(r.step(in).speed_m_s, cfg.cruise_m_s);
  // gone: the car waits obstacle_clear_s after it last held the car, then cruises
  in.obstacle_ahead_m = cfg.front_m + cfg.obstacle_margin_m;
  in.t_us = 1000000;
  r.step(in);
  in.obstacle_ahead_m = -1;
  in.t_us += static_cast<int64_t>(0.5 * cfg.obstacle_clear_s * 1e6);
  out = r.step(in);
  EXPECT_EQ(out.speed_m_s, 0.0);
  EXPECT_EQ(out.reason, "obstacle gone, waiting");
  in.t_us = 1000000 + static_cast<int64_t>(cfg.obstacle_clear_s * 1e6) + 1;
  EXPECT_DOUBLE_EQ(r.step(in).speed_m_s, cfg.cruise_m_s);
  // no fresh scan: blocked
  in.scan_fresh = false;
  out = r.step(in);
  EXPECT_EQ(out.speed_m_s, 0.0);
  EXPECT_EQ(out.reason, "no fresh LIDAR scan");
}

TEST(Obstacle, TheTrackerKeepsAnObstacleAsTheCarMovesAndInTheBlindZone) {
  const Track t = track_for(city(), "city_east");
  const ObstacleConfig cfg;
  const double front_m = RulesConfig{}.front_m;
  const CarPose car = car_at(t, 1.0);
  ObstacleTracker tr;
  tr.on_scan(t, car, scan_of(car, {on_track(t, 1.6, 0.0)}, cfg), cfg, front_m);
  EXPECT_NEAR(tr.ahead_m(t, 1.0), 0.6, 0.02);
  EXPECT_NEAR(tr.ahead_m(t, 1.1), 0.5, 0.02);  // the car moved on 10 cm: 10 cm nearer
  // a clear scan from where the LIDAR could see the place: gone
  tr.on_scan(t, car, scan_of(car, {}, cfg), cfg, front_m);
  EXPECT_LT(tr.ahead_m(t, 1.0), 0.0);
  // seen, then the car is so near that the LIDAR cannot see it (nearer than range_min): kept
  tr.on_scan(t, car, scan_of(car, {on_track(t, 1.6, 0.0)}, cfg), cfg, front_m);
  const CarPose near = car_at(t, 1.46);
  tr.on_scan(t, near, scan_of(near, {}, cfg), cfg, front_m);
  EXPECT_NEAR(tr.ahead_m(t, 1.46), 0.14, 0.02);
}
