// The one pure pursuit (<autodrive/pure_pursuit.h>, <autodrive/pure_pursuit.hpp>): the steering
// law, the two goal rules, projection with progress, and the vehicle limits.
#include <autodrive/angle_wrap.h>
#include <autodrive/angles.hpp>
#include <autodrive/pure_pursuit.h>
#include <autodrive/pure_pursuit.hpp>
#include <autodrive_vehicle.h>
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace {

constexpr double kPi = 3.14159265358979323846;

// A CCW circle of radius r_m, points step_m apart: x0 y0 x1 y1 ... [m].
std::vector<double> circle(double r_m, double step_m) {
  std::vector<double> xy;
  const int n = static_cast<int>(2 * kPi * r_m / step_m);
  for (int i = 0; i < n; i++) {
    xy.push_back(r_m * std::cos(2 * kPi * i / n));
    xy.push_back(r_m * std::sin(2 * kPi * i / n));
  }
  return xy;
}

TEST(Law, VehicleLimitsComeFromTheVehicleDescription) {
  const pp_vehicle_t v = pp_vehicle_default();
  EXPECT_DOUBLE_EQ(v.wheelbase_m, AUTODRIVE_VEHICLE_WHEELBASE_M);
  EXPECT_DOUBLE_EQ(v.steer_limit_rad, AUTODRIVE_VEHICLE_STEER_LIMIT_RAD);
}

TEST(Law, CurvatureIsTwoLateralOverDistanceSquared) {
  // goal 0.3 m ahead and 0.1 m left of a car at the origin heading +x
  EXPECT_NEAR(pp_curvature_to(0, 0, 0, 0.3, 0.1), 2 * 0.1 / (0.09 + 0.01), 1e-12);
  // the same goal seen from a car rotated by 90 deg: the frame turns with it
  EXPECT_NEAR(pp_curvature_to(1, 1, kPi / 2, 0.9, 1.3), 2 * 0.1 / 0.1, 1e-12);
  EXPECT_NEAR(pp_curvature_to(0, 0, 0, 0.3, 0.0), 0.0, 1e-12);             // straight ahead
  EXPECT_NEAR(pp_curvature_to(0, 0, 0, -0.3, 0.1), 2 * 0.1 / 0.1, 1e-12);  // behind: reverse
}

TEST(Law, SteeringIsAtanOfCurvatureTimesWheelbaseClampedToTheLimit) {
  const pp_vehicle_t v = {0.15, 0.5};
  EXPECT_NEAR(pp_steer_for_curvature(2.0, &v), std::atan(0.3), 1e-12);
  EXPECT_NEAR(pp_steer_for_curvature(-2.0, &v), -std::atan(0.3), 1e-12);
  EXPECT_DOUBLE_EQ(pp_steer_for_curvature(100.0, &v), 0.5);
  EXPECT_DOUBLE_EQ(pp_steer_for_curvature(-100.0, &v), -0.5);
  EXPECT_NEAR(pp_steer_to(0, 0, 0, 0.3, 0.1, &v), std::atan(0.15 * 2.0), 1e-12);
  EXPECT_DOUBLE_EQ(autodrive::pursuit_steer_rad(0, 0, 0, 0.3, 0.1, v),
                   pp_steer_to(0, 0, 0, 0.3, 0.1, &v));
}

TEST(Law, LookaheadGrowsWithSpeedEitherWay) {
  EXPECT_DOUBLE_EQ(pp_lookahead_m(0.07, 0.4, 0.0), 0.07);
  EXPECT_DOUBLE_EQ(pp_lookahead_m(0.07, 0.4, 0.2), 0.07 + 0.08);
  EXPECT_DOUBLE_EQ(pp_lookahead_m(0.07, 0.4, -0.2), 0.07 + 0.08);
}

TEST(GoalIndex, FirstSampleAtLeastTheLookaheadAwayFromTheProgressIndex) {
  const std::vector<double> xy = {0, 0, 0.1, 0, 0.2, 0, 0.3, 0, 0.4, 0};
  EXPECT_EQ(pp_goal_index(xy.data(), 5, 0, 0.0, 0.0, 0.25), 3);
  EXPECT_EQ(pp_goal_index(xy.data(), 5, 0, 0.0, 0.0, 0.2), 2);  // at exactly the lookahead
  EXPECT_EQ(pp_goal_index(xy.data(), 5, 4, 0.0, 0.0, 0.1), 4);  // never behind the index
  EXPECT_EQ(pp_goal_index(xy.data(), 5, 0, 0.0, 0.0, 1.0), 5);  // none: n
  EXPECT_EQ(pp_goal_index(xy.data(), 5, -3, 0.0, 0.0, 0.05), 1);
}

TEST(Path, RejectsTooFewPointsAndZeroLength) {
  pp_path_t p;
  char err[128];
  const double one[2] = {0, 0}, same[4] = {1, 1, 1, 1};
  EXPECT_EQ(pp_path_init(&p, one, 1, 0, err, sizeof err), -1);
  EXPECT_NE(std::string(err).find("2 points"), std::string::npos) << err;
  EXPECT_EQ(pp_path_init(&p, same, 2, 0, err, sizeof err), -1);
  EXPECT_NE(std::string(err).find("zero length"), std::string::npos) << err;
  EXPECT_THROW(autodrive::PathTracker({0.0, 0.0}, false), std::invalid_argument);
}

TEST(Path, PointAtWrapsALoopAndExtendsAnOpenPath) {
  const std::vector<double> sq = {0, 0, 1, 0, 1, 1, 0, 1};
  const autodrive::PathTracker loop(sq, true);
  EXPECT_DOUBLE_EQ(loop.length_m(), 4.0);
  auto q = loop.point_at(4.5);
  EXPECT_NEAR(q.first, 0.5, 1e-12);
  EXPECT_NEAR(q.second, 0.0, 1e-12);
  q = loop.point_at(-0.5);
  EXPECT_NEAR(q.first, 0.0, 1e-12);
  EXPECT_NEAR(q.second, 0.5, 1e-12);
  const autodrive::PathTracker open(sq, false);
  EXPECT_DOUBLE_EQ(open.length_m(), 3.0);
  q = open.point_at(3.5);  // past the end along the last segment (towards -x)
  EXPECT_NEAR(q.first, -0.5, 1e-12);
  EXPECT_NEAR(q.second, 1.0, 1e-12);
}

TEST(Path, SteersACircleExactlyForAnyLookahead) {
  const double r_m = 0.6;
  const pp_vehicle_t v = pp_vehicle_default();
  autodrive::PathTracker t(circle(r_m, 0.02), true, v);
  t.reset(r_m, 0.0);
  t.project(r_m, 0.0);
  EXPECT_NEAR(t.cross_track_m(), 0.0, 1e-9);
  for (double ld : {0.1, 0.2, 0.4})
    EXPECT_NEAR(t.steer_rad(r_m, 0.0, kPi / 2, ld), std::atan(v.wheelbase_m / r_m), 2e-3) << ld;
  t.project(r_m + 0.01, 0.0);  // outside a CCW circle: right of it
  EXPECT_NEAR(t.cross_track_m(), -0.01, 1e-4);
}

TEST(Path, ProgressGrowsOverLapsAndEndsAnOpenPath) {
  autodrive::PathTracker loop(circle(0.5, 0.02), true);
  const double len = loop.length_m();
  for (int i = 1; i <= 200; i++) {  // 1.25 laps in small steps
    const double a = 2 * kPi * 1.25 * i / 200;
    loop.project(0.5 * std::cos(a), 0.5 * std::sin(a));
  }
  EXPECT_NEAR(loop.s_m(), 1.25 * len, 0.02);
  EXPECT_TRUE(loop.done());
  autodrive::PathTracker open({0, 0, 1, 0}, false);
  open.project(0.5, 0.1);
  EXPECT_FALSE(open.done());
  EXPECT_NEAR(open.s_m(), 0.5, 1e-12);
  EXPECT_NEAR(open.cross_track_m(), 0.1, 1e-12);
  open.project(1.2, 0.0);
  EXPECT_TRUE(open.done());
  EXPECT_DOUBLE_EQ(open.cross_track_m(), 0.0);
}

// A kinematic bicycle on the rear axle driven by the tracker around a circle stays on it.
TEST(Path, ClosedLoopBicycleConvergesOntoACircle) {
  const double r_m = 0.8, dt_s = 0.02, v_m_s = 0.2;
  const pp_vehicle_t car = pp_vehicle_default();
  autodrive::PathTracker t(circle(r_m, 0.02), true, car);
  double x = r_m + 0.05, y = 0.0, yaw = kPi / 2;  // 5 cm outside, tangent
  t.reset(x, y);
  double worst_late_m = 0.0;
  for (int i = 0; i < 1000; i++) {
    t.project(x, y);
    const double delta = t.steer_rad(x, y, yaw, pp_lookahead_m(0.1, 0.5, v_m_s));
    x += v_m_s * std::cos(yaw) * dt_s;
    y += v_m_s * std::sin(yaw) * dt_s;
    yaw += v_m_s * std::tan(delta) / car.wheelbase_m * dt_s;
    if (i > 500) worst_late_m = std::max(worst_late_m, std::abs(std::hypot(x, y) - r_m));
  }
  EXPECT_LT(worst_late_m, 0.005);
}

// The C wrap (<autodrive/angle_wrap.h>) is the C++ one (<autodrive/angles.hpp>), bit for bit.
TEST(AngleWrap, CIsTheCppWrapInto_MinusPiPi) {
  for (double a = -20.0; a <= 20.0; a += 0.01)
    EXPECT_EQ(autodrive_angle_wrap_rad(a), autodrive::angle_wrap_rad(a)) << a;
  EXPECT_DOUBLE_EQ(autodrive_angle_wrap_rad(kPi), kPi);  // (-pi, pi]: +pi stays
  EXPECT_DOUBLE_EQ(autodrive_angle_wrap_rad(-kPi), kPi);
  EXPECT_NEAR(autodrive_angle_wrap_rad(3 * kPi / 2), -kPi / 2, 1e-12);
  EXPECT_NEAR(autodrive_angle_wrap_rad(-7.0), -7.0 + 2 * kPi, 1e-12);
}

}  // namespace
