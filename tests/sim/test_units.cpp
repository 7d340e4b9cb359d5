// Unit tests of the sim's pure models: parameter loader, tyre curve, motor, servo, Ackermann,
// UART pacing, scripted driver.
#include <gtest/gtest.h>
#include <math.h>
#include <stdio.h>

#include <fstream>
#include <sstream>
#include <string>

#include "drive.h"
#include "script.h"
#include "sim_test_util.h"
#include "tyre.h"
#include "uart.h"
#include "vehicle_params.h"

namespace {

std::string read_all(const std::string &path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// Writes the default parameter file with one line replaced (or appended) and loads it.
std::string load_modified(const std::string &find, const std::string &repl, int *rc) {
  std::string text = read_all(simtest::params_path());
  if (!find.empty()) {
    const size_t at = text.find(find);
    EXPECT_NE(at, std::string::npos) << find;
    const size_t eol = text.find('\n', at);
    text.replace(at, eol - at, repl);
  } else {
    text += repl + "\n";
  }
  const std::string dir = simtest::temp_dir(), path = dir + "/bad.params";
  std::ofstream(path) << text;
  vehicle_params_t p;
  char err[512] = "";
  *rc = vehicle_params_load(path.c_str(), &p, err, sizeof err);
  unlink(path.c_str());
  rmdir(dir.c_str());
  return err;
}

TEST(Params, DefaultFileLoadsWithReferenceFigures) {
  vehicle_params_t p;
  char err[512] = "";
  ASSERT_EQ(vehicle_params_load(simtest::params_path().c_str(), &p, err, sizeof err), 0) << err;
  EXPECT_DOUBLE_EQ(p.wheelbase_m, 0.14154);
  EXPECT_DOUBLE_EQ(p.track_m, 0.153);
  EXPECT_DOUBLE_EQ(p.wheel_radius_m, 0.0325);
  EXPECT_DOUBLE_EQ(p.mass_kg, 2.68);
  EXPECT_EQ(p.tyre_model_paper, 1);
}

TEST(Params, BadFilesNameFileAndKey) {
  int rc = 0;
  std::string e = load_modified("wheelbase_m = 0.14154", "wheelbase_m = abc", &rc);
  EXPECT_EQ(rc, -1);
  EXPECT_NE(e.find("bad.params"), std::string::npos) << e;
  EXPECT_NE(e.find("'wheelbase_m'"), std::string::npos) << e;

  e = load_modified("track_m = 0.153", "", &rc);
  EXPECT_EQ(rc, -1);
  EXPECT_NE(e.find("'track_m': missing"), std::string::npos) << e;

  e = load_modified("", "wheel_colour = red", &rc);
  EXPECT_EQ(rc, -1);
  EXPECT_NE(e.find("'wheel_colour': unknown"), std::string::npos) << e;

  e = load_modified("", "mass_kg = 3", &rc);
  EXPECT_EQ(rc, -1);
  EXPECT_NE(e.find("'mass_kg': given twice"), std::string::npos) << e;

  e = load_modified("imu_pos_m = 0.03995 0 0.08313", "imu_pos_m = 0.03995 0", &rc);
  EXPECT_EQ(rc, -1);
  EXPECT_NE(e.find("'imu_pos_m'"), std::string::npos) << e;

  e = load_modified("mass_kg = 2.68", "mass_kg = -2", &rc);
  EXPECT_EQ(rc, -1);
  EXPECT_NE(e.find("'mass_kg': must be > 0"), std::string::npos) << e;

  e = load_modified("tyre_model = paper", "tyre_model = magic", &rc);
  EXPECT_EQ(rc, -1);
  EXPECT_NE(e.find("'tyre_model'"), std::string::npos) << e;

  e = load_modified("com_to_front_m = 0.06226", "com_to_front_m = 0.5", &rc);
  EXPECT_EQ(rc, -1);
  EXPECT_NE(e.find("'com_to_front_m'"), std::string::npos) << e;

  vehicle_params_t p;
  char err[256];
  EXPECT_EQ(vehicle_params_load("/nonexistent/x.params", &p, err, sizeof err), -1);
  EXPECT_NE(std::string(err).find("/nonexistent/x.params"), std::string::npos);
}

TEST(Tyre, CurvePassesThroughItsPointsAndIsOdd) {
  const tyre_curve_t c = {0.4, 1.0, 0.8, 0.5};
  EXPECT_DOUBLE_EQ(tyre_curve_eval(&c, 0.0), 0.0);
  EXPECT_NEAR(tyre_curve_eval(&c, 0.4), 1.0, 1e-12);
  EXPECT_NEAR(tyre_curve_eval(&c, 0.8), 0.5, 1e-12);
  EXPECT_NEAR(tyre_curve_eval(&c, 5.0), 0.5, 1e-12);
  EXPECT_NEAR(tyre_curve_eval(&c, -0.3), -tyre_curve_eval(&c, 0.3), 1e-12);
  // rising to the extremum, falling to the asymptote, continuous at the joints
  EXPECT_LT(tyre_curve_eval(&c, 0.2), tyre_curve_eval(&c, 0.3));
  EXPECT_GT(tyre_curve_eval(&c, 0.5), tyre_curve_eval(&c, 0.7));
  EXPECT_NEAR(tyre_curve_eval(&c, 0.4 - 1e-9), tyre_curve_eval(&c, 0.4 + 1e-9), 1e-6);
  EXPECT_NEAR(tyre_curve_eval(&c, 0.8 - 1e-9), tyre_curve_eval(&c, 0.8 + 1e-9), 1e-6);
}

TEST(Tyre, ForcesOpposeSlipAndStayInTheFrictionCircle) {
  const tyre_curve_t lon = {0.4, 1.0, 0.8, 0.5}, lat = {0.2, 1.0, 0.5, 0.75};
  tyre_in_t in = {};
  in.v_x_m_s = 0.2;
  in.v_y_m_s = 0.05;
  in.omega_r_m_s = 0.3;  // spinning faster than the ground: drive force forward
  in.fz_n = 6.0;
  in.mu = 0.9;
  in.v_min_m_s = 0.05;
  in.m_long_kg = 100.0;  // clamp out of the way
  in.m_lat_kg = 100.0;
  in.dt_s = 0.001;
  double fx, fy;
  tyre_force(&lon, &lat, &in, &fx, &fy);
  EXPECT_GT(fx, 0.0);
  EXPECT_LT(fy, 0.0);  // sliding left -> pushed right
  EXPECT_LE(hypot(fx, fy), 0.9 * 6.0 + 1e-9);
  // the clamp never lets one step reverse a tiny slip velocity
  in.m_long_kg = 0.01;
  in.m_lat_kg = 0.01;
  tyre_force(&lon, &lat, &in, &fx, &fy);
  EXPECT_LE(fabs(fx), 0.01 * 0.1 / 0.001 + 1e-9);
  EXPECT_LE(fabs(fy), 0.01 * 0.05 / 0.001 + 1e-9);
  in.fz_n = 0.0;  // airborne
  tyre_force(&lon, &lat, &in, &fx, &fy);
  EXPECT_EQ(fx, 0.0);
  EXPECT_EQ(fy, 0.0);
}

TEST(Drive, MotorBackEmfAndBrake) {
  const motor_model_t m = {0.2, 8.0, 12.0};
  EXPECT_NEAR(motor_torque_nm(&m, 255, 0, 0, 12.0, 0.0), 0.2, 1e-12);   // stall
  EXPECT_NEAR(motor_torque_nm(&m, 255, 0, 0, 12.0, 8.0), 0.0, 1e-12);   // no-load speed
  EXPECT_NEAR(motor_torque_nm(&m, 255, 1, 0, 12.0, 0.0), -0.2, 1e-12);  // reverse
  EXPECT_LT(motor_torque_nm(&m, 200, 0, 1, 12.0, 4.0), 0.0);            // brake opposes motion
  EXPECT_NEAR(motor_torque_nm(&m, 200, 0, 1, 12.0, 0.0), 0.0, 1e-12);   // duty ignored
}

TEST(Drive, ServoMappingRateLimitAndAckermann) {
  EXPECT_NEAR(steer_command_rad(2000, 1500, 500, 0.5236), 0.5236, 1e-12);
  EXPECT_NEAR(steer_command_rad(1250, 1500, 500, 0.5236), -0.2618, 1e-12);
  EXPECT_NEAR(steer_command_rad(2600, 1500, 500, 0.5236), 0.5236, 1e-12);
  double a = 0.0;
  for (int k = 0; k < 100; k++) a = steer_rate_limit(a, 0.5, 0.805, 0.001);
  EXPECT_NEAR(a, 0.0805, 1e-9);
  double l, r;
  const double L = 0.14154, T = 0.153, d = 0.3;
  steer_ackermann(d, L, T, &l, &r);
  EXPECT_GT(l, d);  // left turn: the inner (left) wheel steers more
  EXPECT_LT(r, d);
  // both wheels point at the same centre on the rear axle line
  EXPECT_NEAR(L / tan(l) + T / 2, L / tan(d), 1e-9);
  EXPECT_NEAR(L / tan(r) - T / 2, L / tan(d), 1e-9);
  steer_ackermann(-d, L, T, &l, &r);
  EXPECT_LT(r, -d);  // right turn: right wheel is inner
  steer_ackermann(0.0, L, T, &l, &r);
  EXPECT_EQ(l, 0.0);
  EXPECT_EQ(r, 0.0);
}

TEST(Uart, PacesBytesAtTheWireRate) {
  static uart_queue_t q;
  uart_init(&q, 500000);
  uint8_t in[300], out[300];
  for (int i = 0; i < 300; i++) in[i] = (uint8_t)i;
  uart_push(&q, in, 300);
  EXPECT_EQ(uart_pop(&q, 1000, out, sizeof out), 50u);  // 20 us per byte
  EXPECT_EQ(out[0], 0);
  EXPECT_EQ(out[49], 49);
  EXPECT_EQ(uart_pop(&q, 100, out, sizeof out), 5u);
  EXPECT_EQ(out[0], 50);
  // an idle line banks no wire time
  static uart_queue_t q2;
  uart_init(&q2, 500000);
  EXPECT_EQ(uart_pop(&q2, 100000, out, sizeof out), 0u);
  uart_push(&q2, in, 10);
  EXPECT_LE(uart_pop(&q2, 20, out, sizeof out), 2u);
}

TEST(Script, ArmsThenDrivesAndParsesErrors) {
  script_t s;
  char err[256];
  ASSERT_EQ(script_parse(&s, "constant:throttle=0.5,steering=-0.25,stop_after=1", err, sizeof err),
            0)
      << err;
  protocol_parser_t p;
  protocol_parser_init(&p);
  struct Got {
    int n = 0;
    protocol_command_t last{};
  } got;
  uint8_t buf[2 * PROTOCOL_MAX_FRAME];
  for (int64_t t = 0; t < 2000000; t += 1000) {
    const size_t n = script_poll(&s, t, buf, sizeof buf);
    protocol_parser_feed(
        &p, buf, n,
        [](const protocol_frame_t *f, void *ctx) {
          auto *g = static_cast<Got *>(ctx);
          ASSERT_EQ(f->id, PROTOCOL_ID_COMMAND);
          ASSERT_EQ(protocol_command_unpack(f->payload, f->len, &g->last), 0);
          if (g->n < 3) {
            EXPECT_EQ(g->last.flags, 0);  // arming: engaged=0 first
          }
          g->n++;
        },
        &got);
  }
  EXPECT_EQ(got.n, 50);  // 50 Hz for 1 s, then quiet
  EXPECT_EQ(got.last.flags, PROTOCOL_CMD_ENGAGED);
  EXPECT_EQ(got.last.throttle_milli, 500);
  EXPECT_EQ(got.last.steering_milli, -250);
  EXPECT_EQ(p.stats.bad_crc, 0u);
  EXPECT_EQ(script_parse(&s, "constant:throttle=2", err, sizeof err), -1);
  EXPECT_NE(std::string(err).find("throttle"), std::string::npos);
  EXPECT_EQ(script_parse(&s, "wiggle:x=1", err, sizeof err), -1);
  EXPECT_EQ(script_parse(&s, "constant:speed=1", err, sizeof err), -1);
  EXPECT_NE(std::string(err).find("speed"), std::string::npos);
}

TEST(Script, RouteTakesLapsAndPerturbation) {
  script_t s;
  char err[256];
  ASSERT_EQ(script_parse(&s, "route:loop_ccw,laps=3,perturb=0.4", err, sizeof err), 0) << err;
  EXPECT_EQ(s.laps, 3);
  EXPECT_DOUBLE_EQ(s.perturb, 0.4);
  ASSERT_EQ(script_parse(&s, "route:loop_ccw", err, sizeof err), 0) << err;
  EXPECT_EQ(s.laps, 1);  // one lap, no perturbation unless asked
  EXPECT_DOUBLE_EQ(s.perturb, 0.0);
  EXPECT_EQ(s.lane_shift, 0);  // its own lane unless asked
  ASSERT_EQ(script_parse(&s, "route:loop_ccw,lane_shift=-1", err, sizeof err), 0) << err;
  EXPECT_EQ(s.lane_shift, -1);
  for (const char *bad :
       {"route:a,laps=0", "route:a,laps=1.5", "route:a,perturb=1.5", "constant:throttle=0.1,laps=2",
        "route:a,lane_shift=0.5", "route:a,lane_shift=4", "constant:throttle=0.1,lane_shift=1"}) {
    EXPECT_EQ(script_parse(&s, bad, err, sizeof err), -1) << bad;
    EXPECT_NE(std::string(err).find(bad), std::string::npos) << err;  // names the spec
  }
}

}  // namespace
