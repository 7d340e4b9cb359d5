// C++ face of the one "next light and sign ahead" (<autodrive/road_rules.h>): the network owned
// by a class, its input as vectors, errors as exceptions.
#pragma once

#include <autodrive/road_rules.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace autodrive::road {

struct LaneInput {
  std::vector<road_point_t> centre_line;  // driving order [m, m, rad]
  double half_width_m = 0;
};

struct RouteInput {
  std::vector<int> lanes;  // lane indices in driving order
  bool loop = false;
};

class Network {
 public:
  // Throws std::invalid_argument with the library's message for bad input.
  Network(const std::vector<LaneInput> &lanes, const std::vector<road_light_t> &lights,
          const std::vector<road_sign_t> &signs, const std::vector<RouteInput> &routes) {
    std::vector<road_lane_t> c_lanes;
    for (const LaneInput &l : lanes)
      c_lanes.push_back(
          {l.centre_line.data(), static_cast<int>(l.centre_line.size()), l.half_width_m});
    std::vector<road_route_t> c_routes;
    for (const RouteInput &r : routes)
      c_routes.push_back({r.lanes.data(), static_cast<int>(r.lanes.size()), r.loop ? 1 : 0});
    char err[256] = "";
    net_.reset(road_net_create(c_lanes.data(), static_cast<int>(c_lanes.size()), lights.data(),
                               static_cast<int>(lights.size()), signs.data(),
                               static_cast<int>(signs.size()), c_routes.data(),
                               static_cast<int>(c_routes.size()), err, sizeof err));
    if (!net_) throw std::invalid_argument(err);
  }

  int lane_count() const { return road_lane_count(net_.get()); }
  double lane_length_m(int lane) const { return road_lane_length_m(net_.get(), lane); }
  // The lights and signs on a lane, in order of s.
  std::vector<road_anchor_t> anchors(int lane) const {
    const road_anchor_t *a = nullptr;
    const int n = road_lane_anchors(net_.get(), lane, &a);
    return std::vector<road_anchor_t>(a, a + n);
  }
  // false when the car is on no lane.
  bool place(double x_m, double y_m, double yaw_rad, int route, int last_lane,
             road_place_t &out) const {
    return road_place_car(net_.get(), x_m, y_m, yaw_rad, route, last_lane, &out) != 0;
  }
  road_ahead_t ahead(const road_place_t &place, int route,
                     double horizon_m = ROAD_HORIZON_M) const {
    return road_walk_ahead(net_.get(), &place, route, horizon_m);
  }

 private:
  struct Destroy {
    void operator()(road_net_t *n) const { road_net_destroy(n); }
  };
  std::unique_ptr<road_net_t, Destroy> net_;
};

}  // namespace autodrive::road
