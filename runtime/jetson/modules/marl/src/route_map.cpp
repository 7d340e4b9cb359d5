#include <autodrive/marl/route_map.hpp>

#include <autodrive/angles.hpp>

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <limits>
#include <stdexcept>

namespace autodrive::marl {

namespace {
nlohmann::json read_json(const std::string &path) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot be read (a map's JSON sidecar)");
  try {
    return nlohmann::json::parse(f);
  } catch (const std::exception &e) {
    throw std::runtime_error(path + ": not JSON: " + e.what());
  }
}
}  // namespace

autodrive::autonomy::Path Route::path() const {
  autodrive::autonomy::Path p;
  for (size_t i = 0; i < points.size(); ++i) {
    autodrive::autonomy::PathPoint q;
    q.pose = points[i];
    if (i + 1 < points.size()) {
      const double ds = s_m[i + 1] - s_m[i];
      const double dyaw = autodrive::angle_wrap_rad(points[i + 1].yaw_rad - points[i].yaw_rad);
      q.curvature_1pm = ds > 1e-9 ? dyaw / ds : 0.0;
    }
    p.push_back(q);
  }
  return p;
}

size_t Route::nearest(double x_m, double y_m) const {
  size_t best = 0;
  double best_d = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < points.size(); ++i) {
    const double d = std::hypot(points[i].x_m - x_m, points[i].y_m - y_m);
    if (d < best_d) best_d = d, best = i;
  }
  return best;
}

bool ConflictZone::contains(double x_m, double y_m) const {
  return std::abs(x_m - cx_m) < half_m && std::abs(y_m - cy_m) < half_m;
}

Route read_route(const std::string &map_json, const std::string &name) {
  const nlohmann::json j = read_json(map_json);
  if (!j.contains("routes") || !j["routes"].is_array())
    throw std::runtime_error(map_json + ": routes: missing (this map has no named routes)");
  std::string names;
  for (const auto &r : j["routes"]) {
    const std::string n = r.value("name", "");
    names += (names.empty() ? "" : ", ") + n;
    if (n != name) continue;
    Route out;
    out.name = name;
    out.half_width_m = r.at("half_width_m").get<double>();
    if (!(out.half_width_m > 0.0))
      throw std::runtime_error(map_json + ": route " + name + ": half_width_m must be > 0");
    const auto &poly = r.at("polyline_m");
    for (size_t i = 0; i < poly.size(); ++i) {
      autodrive::autonomy::Pose2 p{poly[i].at(0).get<double>(), poly[i].at(1).get<double>(), 0.0};
      out.points.push_back(p);
    }
    if (out.points.size() < 2)
      throw std::runtime_error(map_json + ": route " + name + ": < 2 points");
    out.s_m.assign(out.points.size(), 0.0);
    for (size_t i = 0; i < out.points.size(); ++i) {
      const size_t a = i + 1 < out.points.size() ? i : i - 1;
      out.points[i].yaw_rad = std::atan2(out.points[a + 1].y_m - out.points[a].y_m,
                                         out.points[a + 1].x_m - out.points[a].x_m);
      if (i > 0)
        out.s_m[i] = out.s_m[i - 1] + std::hypot(out.points[i].x_m - out.points[i - 1].x_m,
                                                 out.points[i].y_m - out.points[i - 1].y_m);
    }
    return out;
  }
  throw std::runtime_error(map_json + ": no route named '" + name + "' (routes: " + names + ")");
}

ConflictZone read_conflict_zone(const std::string &map_json, double margin_m) {
  const nlohmann::json j = read_json(map_json);
  for (const auto &t : j.value("tiles", nlohmann::json::array())) {
    if (t.value("type", "") != "cross") continue;
    ConflictZone z;
    z.cx_m = t.at("centre_m").at(0).get<double>();
    z.cy_m = t.at("centre_m").at(1).get<double>();
    z.half_m = t.at("road_width_m").get<double>() / 2.0 + margin_m;
    return z;
  }
  throw std::runtime_error(map_json + ": tiles: no 4-way (cross) tile, so no conflict zone");
}

}  // namespace autodrive::marl
