// The city as the behaviour layer sees it, read from a map's sidecar JSON (written by
// tools/gen-maps from maps/<map>.yaml; never typed here): lane centre lines,
// named routes, stop lines, traffic lights and signs. Lights and signs stand on the lanes where the
// one "next light and sign ahead" (<autodrive/road_rules.hpp>, the SCM's too) puts them. A route
// (a named one, or a chain of lanes) becomes a Track: one polyline with arc length, the stops on
// it (each light's stop line, each stop sign's stop line) and its speed zones (speed-limit and
// curve signs).
#pragma once

#include <autodrive/road_rules.hpp>
#include <autodrive/strict_yaml.hpp>

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace autodrive::behaviour {

using Error = autodrive::InputError;

struct Point {
  double x_m = 0, y_m = 0, heading_rad = 0;
};

struct Lane {
  std::string name;
  std::vector<Point> centre_line;
  double half_width_m = 0;
  int index = 0;  // its place in the sidecar's list (the road network's lane index)
};

struct StopLine {
  std::string name, lane;
  double x_m = 0, y_m = 0;
};

struct Light {
  int id = 0;
  std::string name, lane, stop_line;
};

struct Sign {
  int id = 0;
  std::string name, kind, lane;  // lane empty: a sign at a pose
  double x_m = 0, y_m = 0, yaw_rad = 0;
  double speed_limit_m_s = -1;  // speed_limit signs only
};

struct NamedRoute {
  std::string name;
  std::vector<std::string> lanes;
  bool loop = false;
};

struct CityMap {
  std::string file, name;
  std::map<std::string, Lane> lanes;
  std::vector<StopLine> stop_lines;
  std::vector<Light> lights;
  std::vector<Sign> signs;
  std::map<std::string, NamedRoute> routes;
  std::vector<std::string> lane_order;   // lane names in the sidecar's order
  std::vector<std::string> route_order;  // route names in the sidecar's order
  // where the lights and signs stand, and the walk ahead (shared: a CityMap copies cheaply)
  std::shared_ptr<const autodrive::road::Network> roads;
};

// Reads a sidecar JSON; Error naming the file and the element when something is missing.
CityMap load_city_map(const std::string &path);

struct TrackPoint {
  double x_m, y_m, heading_rad, s_m;
};

struct Stop {
  enum class Kind { light, stop_sign };
  Kind kind = Kind::light;
  double s_m = 0;     // the stop line's arc length along the track [m]
  int light_id = -1;  // lights only
  std::string name;   // the stop line's name
};

struct SpeedZone {
  double s0_m = 0, s1_m = 0;  // from, to along the track [m] (s1 may pass the lap's end)
  double limit_m_s = 0;       // < 0: the curve speed of the rules
  std::string why;            // the sign's name and kind
};

struct Track {
  std::string name;
  bool loop = false;
  double length_m = 0;
  std::vector<TrackPoint> points;
  std::vector<Stop> stops;  // in order of s
  std::vector<SpeedZone> zones;
};

// The track of a chain of lanes (each must start where the previous ends, within 5 mm; for a
// loop also the first where the last ends). Error naming the lane that does not connect.
Track build_track(const CityMap &m, const std::string &name, const std::vector<std::string> &lanes,
                  bool loop);
// The track of a route: a named route of the map, or "lanes:A,B,C" (a loop of those lanes).
Track track_for(const CityMap &m, const std::string &route);

struct Projection {
  double s_m = 0;        // arc length of the nearest point [m], in [0, length)
  double lateral_m = 0;  // signed distance, + left of the track [m]
  double dist_m = 0;     // |lateral|
};
// Nearest point of the track to (x, y), searched within [s_hint - back, s_hint + ahead] (wrapping
// on a loop); s_hint < 0 searches the whole track.
Projection project(const Track &t, double x_m, double y_m, double s_hint_m = -1,
                   double back_m = 0.3, double ahead_m = 1.0);
// The track point at arc length s (wrapped on a loop, clamped otherwise).
TrackPoint point_at(const Track &t, double s_m);

}  // namespace autodrive::behaviour
