// The one place autodrive-marl calls the MARL core: the observation builder and the
// time-to-collision (TTC) safety shield. The core itself is the C11 library
// autodrive_marl_core (runtime/jetson/marl_core/, owned by the marl-train branch). Until that
// branch is merged, src/core_adapter.cpp holds an INTERIM implementation to the contract in
// /work/wt/CONTRACT-demos.md (observation layout "interim-0"); on the merge it forwards to
// <autodrive/marl_core.h> and the interim code goes (runtime/jetson/marl/README.md).
#pragma once

#include <string>
#include <vector>

namespace marl {

struct CarState {
  double x_m = 0, y_m = 0, yaw_rad = 0;  // map frame [m, m, rad]
  double speed_m_s = 0;                  // [m/s], + forward
};

struct Goal {
  double x_m = 0, y_m = 0;  // map frame [m]
};

// Observation layout interim-0: own goal in the own frame over kGoalScaleM, own speed over the
// top speed, then kPeerSlots slots, nearest peer first: relative x, y in the own frame over
// kPeerScaleM, sin and cos of the relative yaw, speed over the top speed, 1 (0 for an empty
// slot, all zeros).
constexpr int kPeerSlots = 3;
constexpr int kObsDim = 3 + 6 * kPeerSlots;
constexpr double kGoalScaleM = 4.0, kPeerScaleM = 2.0;
const char *obs_layout_name();
std::vector<float> build_observation(const CarState &own, const Goal &goal,
                                     const std::vector<CarState> &peers);

struct ShieldParams {
  double horizon_s = 2.0;      // prediction horizon [s]
  double step_s = 0.05;        // prediction step [s]
  double min_ttc_s = 1.2;      // brake when a predicted contact is nearer than this [s]
  double contact_m = 0.25;     // chassis-centre distance counted as a contact [m] (~ car length)
};

struct ShieldResult {
  double throttle = 0, steering = 0;  // the command to send
  bool intervened = false;            // the shield replaced the intended throttle
  double ttc_s = 1e9;                 // predicted time to the first contact [s] (1e9: none)
};

// Predicts own car (at the speed the intended throttle asks for, turning with the intended
// steering) and every peer (constant speed and heading) over the horizon; brakes (throttle 0,
// steering kept) when a contact is predicted within min_ttc_s.
ShieldResult shield(const CarState &own, double throttle, double steering,
                    const std::vector<CarState> &peers, const ShieldParams &p = ShieldParams{});

// The car's top speed [m/s] at throttle 1 (motor no-load speed x wheel radius, vehicle/nigel.params).
double top_speed_m_s();

}  // namespace marl
