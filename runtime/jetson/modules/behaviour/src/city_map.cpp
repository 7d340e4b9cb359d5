#include <autodrive/behaviour/city_map.hpp>

#include <autodrive/angles.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

namespace autodrive::behaviour {

namespace {

constexpr double kConnectTolM = 0.005;  // lanes of a chain meet within this [m]
constexpr double kCurveRad = 0.5;       // a lane turning more than this is a curve [rad]

using nlohmann::json;

const json &need(const json &j, const char *key, const std::string &where) {
  if (!j.is_object() || !j.contains(key)) throw Error(where + ": missing key '" + key + "'");
  return j.at(key);
}

double num(const json &j, const char *key, const std::string &where) {
  const json &v = need(j, key, where);
  if (!v.is_number()) throw Error(where + ": '" + key + "' is not a number");
  return v.get<double>();
}

std::string str(const json &j, const char *key, const std::string &where) {
  const json &v = need(j, key, where);
  if (!v.is_string()) throw Error(where + ": '" + key + "' is not a string");
  return v.get<std::string>();
}

// A point given as [x, y] [m].
void xy(const json &j, const char *key, const std::string &where, double &x_m, double &y_m) {
  const json &v = need(j, key, where);
  if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number())
    throw Error(where + ": " + key + " is not [x, y]");
  x_m = v[0].get<double>();
  y_m = v[1].get<double>();
}

// Arc length along the lane's centre line of the point nearest to (x, y).
double s_on_lane(const Lane &l, double x, double y) {
  double best = 1e18, best_s = 0, s = 0;
  for (size_t i = 0; i + 1 < l.centre_line.size(); ++i) {
    const Point &a = l.centre_line[i], &b = l.centre_line[i + 1];
    const double dx = b.x_m - a.x_m, dy = b.y_m - a.y_m, len = std::hypot(dx, dy);
    double u = len > 0 ? ((x - a.x_m) * dx + (y - a.y_m) * dy) / (len * len) : 0;
    u = std::clamp(u, 0.0, 1.0);
    const double d = std::hypot(a.x_m + u * dx - x, a.y_m + u * dy - y);
    if (d < best) best = d, best_s = s + u * len;
    s += len;
  }
  return best_s;
}

double lane_length(const Lane &l) {
  double s = 0;
  for (size_t i = 0; i + 1 < l.centre_line.size(); ++i)
    s += std::hypot(l.centre_line[i + 1].x_m - l.centre_line[i].x_m,
                    l.centre_line[i + 1].y_m - l.centre_line[i].y_m);
  return s;
}

int lane_index(const CityMap &m, const std::string &lane, const std::string &where) {
  const auto it = m.lanes.find(lane);
  if (it == m.lanes.end())
    throw Error(m.file + ": " + where + ": lane '" + lane + "' is not on the map");
  return it->second.index;
}

// The one "next light and sign ahead" on this map: lights at their stop lines, signs beside
// their lanes, the named routes.
std::shared_ptr<const autodrive::road::Network> road_network(const CityMap &m) {
  std::vector<autodrive::road::LaneInput> lanes;
  for (const std::string &name : m.lane_order) {
    const Lane &l = m.lanes.at(name);
    autodrive::road::LaneInput in;
    for (const Point &p : l.centre_line) in.centre_line.push_back({p.x_m, p.y_m, p.heading_rad});
    in.half_width_m = l.half_width_m;
    lanes.push_back(in);
  }
  std::vector<road_light_t> lights;
  for (const Light &l : m.lights) {
    const std::string where = "traffic light " + std::to_string(l.id);
    const auto sl = std::find_if(m.stop_lines.begin(), m.stop_lines.end(),
                                 [&](const StopLine &x) { return x.name == l.stop_line; });
    if (sl == m.stop_lines.end())
      throw Error(m.file + ": " + where + ": stop line '" + l.stop_line + "' is not on the map");
    lights.push_back({l.id, lane_index(m, sl->lane, where), sl->x_m, sl->y_m});
  }
  std::vector<road_sign_t> signs;
  for (const Sign &g : m.signs)
    signs.push_back({g.id,
                     g.lane.empty() ? -1 : lane_index(m, g.lane, "sign " + std::to_string(g.id)),
                     g.x_m, g.y_m, g.yaw_rad, g.speed_limit_m_s});
  std::vector<autodrive::road::RouteInput> routes;
  for (const std::string &name : m.route_order) {
    autodrive::road::RouteInput r;
    for (const std::string &l : m.routes.at(name).lanes)
      r.lanes.push_back(lane_index(m, l, "route " + name));
    r.loop = m.routes.at(name).loop;
    routes.push_back(r);
  }
  try {
    return std::make_shared<const autodrive::road::Network>(lanes, lights, signs, routes);
  } catch (const std::invalid_argument &e) {
    throw Error(m.file + ": " + e.what());
  }
}

}  // namespace

CityMap load_city_map(const std::string &path) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot be opened (the map's sidecar JSON, tools/gen-maps)");
  json j;
  try {
    in >> j;
  } catch (const json::exception &e) {
    throw Error(path + ": is not valid JSON: " + e.what());
  }
  CityMap m;
  m.file = path;
  m.name = str(j, "name", path);
  for (const json &l : need(j, "lanes", path)) {
    Lane lane;
    lane.name = str(l, "name", path + ": lanes[]");
    const std::string where = path + ": lane " + lane.name;
    for (const json &p : need(l, "centre_line", where))
      lane.centre_line.push_back(
          {num(p, "x_m", where), num(p, "y_m", where), num(p, "heading_rad", where)});
    if (lane.centre_line.size() < 2) throw Error(where + ": fewer than 2 centre-line points");
    lane.half_width_m = num(l, "half_width_m", where);
    lane.index = static_cast<int>(m.lane_order.size());
    if (m.lanes.count(lane.name)) throw Error(where + ": appears twice");
    m.lane_order.push_back(lane.name);
    m.lanes[lane.name] = lane;
  }
  for (const json &s : need(j, "stop_lines", path)) {
    StopLine sl;
    sl.name = str(s, "name", path + ": stop_lines[]");
    const std::string where = path + ": stop line " + sl.name;
    sl.lane = str(s, "lane", where);
    xy(s, "centre_m", where, sl.x_m, sl.y_m);
    m.stop_lines.push_back(sl);
  }
  for (const json &t : need(j, "traffic_lights", path)) {
    Light l;
    l.id = static_cast<int>(num(t, "id", path + ": traffic_lights[]"));
    const std::string where = path + ": traffic light " + std::to_string(l.id);
    l.name = str(t, "name", where);
    l.lane = str(t, "lane", where);
    l.stop_line = str(t, "stop_line", where);
    m.lights.push_back(l);
  }
  for (const json &s : need(j, "signs", path)) {
    Sign g;
    g.id = static_cast<int>(num(s, "id", path + ": signs[]"));
    const std::string where = path + ": sign " + std::to_string(g.id);
    g.name = str(s, "name", where);
    g.kind = str(s, "kind", where);
    g.lane = need(s, "lane", where).is_null() ? "" : str(s, "lane", where);
    xy(s, "position_m", where, g.x_m, g.y_m);
    g.yaw_rad = num(s, "yaw_rad", where);
    if (g.kind == "speed_limit") g.speed_limit_m_s = num(s, "speed_limit_m_s", where);
    m.signs.push_back(g);
  }
  for (const json &r : need(j, "routes", path)) {
    NamedRoute nr;
    nr.name = str(r, "name", path + ": routes[]");
    const std::string where = path + ": route " + nr.name;
    for (const json &l : need(r, "lanes", where)) nr.lanes.push_back(l.get<std::string>());
    nr.loop = need(r, "loop", where).get<bool>();
    m.route_order.push_back(nr.name);
    m.routes[nr.name] = nr;
  }
  m.roads = road_network(m);
  return m;
}

Track build_track(const CityMap &m, const std::string &name, const std::vector<std::string> &lanes,
                  bool loop) {
  const std::string where = m.file + ": route " + name;
  if (lanes.empty()) throw Error(where + ": no lanes");
  Track t;
  t.name = name;
  t.loop = loop;
  std::map<std::string, double> lane_s0;  // arc length where each lane starts on the track
  std::vector<std::pair<double, const Lane *>> placed;
  double s = 0;
  for (size_t k = 0; k < lanes.size(); ++k) {
    auto it = m.lanes.find(lanes[k]);
    if (it == m.lanes.end()) throw Error(where + ": lane '" + lanes[k] + "' is not on the map");
    const Lane &l = it->second;
    if (!t.points.empty()) {
      const TrackPoint &e = t.points.back();
      const double gap =
          std::hypot(l.centre_line.front().x_m - e.x_m, l.centre_line.front().y_m - e.y_m);
      if (gap > kConnectTolM) {
        std::ostringstream o;
        o << where << ": lane '" << l.name << "' does not start where '" << lanes[k - 1]
          << "' ends (" << gap << " m apart)";
        throw Error(o.str());
      }
    }
    if (lane_s0.count(l.name)) throw Error(where + ": lane '" + l.name + "' appears twice");
    lane_s0[l.name] = s;
    placed.push_back({s, &l});
    for (size_t i = t.points.empty() ? 0 : 1; i < l.centre_line.size(); ++i) {
      const Point &p = l.centre_line[i];
      if (!t.points.empty())
        s += std::hypot(p.x_m - t.points.back().x_m, p.y_m - t.points.back().y_m);
      t.points.push_back({p.x_m, p.y_m, p.heading_rad, s});
    }
  }
  if (loop) {
    const TrackPoint &a = t.points.front(), &e = t.points.back();
    const double gap = std::hypot(a.x_m - e.x_m, a.y_m - e.y_m);
    if (gap > kConnectTolM)
      throw Error(where + ": a loop, but its first lane does not start where its last ends");
    t.points.pop_back();  // the start point closes the loop
  }
  t.length_m = s;
  // Stops and zones where the road network puts the lights and signs on the track's lanes:
  // each light at its stop line; each stop sign at its lane's stop line (or at the sign itself
  // when the lane has none).
  for (const auto &[s0, lane] : placed) {
    for (const road_anchor_t &a : m.roads->anchors(lane->index)) {
      const double s_at = s0 + a.s_m;
      if (a.kind == ROAD_LIGHT) {
        const Light &l = m.lights[static_cast<size_t>(a.index)];
        t.stops.push_back({Stop::Kind::light, s_at, l.id, l.stop_line});
        continue;
      }
      const Sign &g = m.signs[static_cast<size_t>(a.index)];
      if (g.kind == "stop") {
        const auto sl = std::find_if(m.stop_lines.begin(), m.stop_lines.end(),
                                     [&](const StopLine &x) { return x.lane == g.lane; });
        const double s_stop =
            sl == m.stop_lines.end() ? s_at : s0 + s_on_lane(*lane, sl->x_m, sl->y_m);
        t.stops.push_back(
            {Stop::Kind::stop_sign, s_stop, -1, sl == m.stop_lines.end() ? g.name : sl->name});
      } else if (g.kind == "speed_limit") {
        // Holds from the sign to the end of its lane (the rest of its road tile).
        t.zones.push_back(
            {s_at, s0 + lane_length(*lane), g.speed_limit_m_s, g.name + " speed_limit"});
      } else if (g.kind == "curve_left" || g.kind == "curve_right") {
        // From the sign through the end of the first curved lane after it.
        double s1 = -1;
        for (size_t k = 0; k < placed.size() * 2 && s1 < 0; ++k) {
          const auto &[c0, l] = placed[k % placed.size()];
          const double base = c0 + (k >= placed.size() ? t.length_m : 0.0);
          const double turn = std::abs(autodrive::angle_wrap_rad(
              l->centre_line.back().heading_rad - l->centre_line.front().heading_rad));
          if (base + 1e-6 >= s_at && turn > kCurveRad) s1 = base + lane_length(*l);
          if (!loop && k + 1 >= placed.size()) break;
        }
        if (s1 > 0) t.zones.push_back({s_at, s1, -1.0, g.name + " " + g.kind});
      }
    }
  }
  std::sort(t.stops.begin(), t.stops.end(),
            [](const Stop &a, const Stop &b) { return a.s_m < b.s_m; });
  return t;
}

Track track_for(const CityMap &m, const std::string &route) {
  const std::string prefix = "lanes:";
  if (route.rfind(prefix, 0) == 0) {
    std::vector<std::string> lanes;
    std::stringstream ss(route.substr(prefix.size()));
    std::string item;
    while (std::getline(ss, item, ',')) lanes.push_back(item);
    return build_track(m, route, lanes, true);
  }
  auto it = m.routes.find(route);
  if (it == m.routes.end()) {
    std::string names;
    for (const auto &[n, r] : m.routes) names += (names.empty() ? "" : ", ") + n;
    throw Error(m.file + ": no route '" + route + "' (routes: " + names +
                "; or lanes:A,B,... for a loop of lanes)");
  }
  return build_track(m, route, it->second.lanes, it->second.loop);
}

TrackPoint point_at(const Track &t, double s) {
  if (t.loop)  // on into the closing segment (the last point back to the first)
    s = std::fmod(std::fmod(s, t.length_m) + t.length_m, t.length_m);
  else
    s = std::clamp(s, 0.0, t.points.back().s_m);
  auto it = std::upper_bound(t.points.begin(), t.points.end(), s,
                             [](double v, const TrackPoint &p) { return v < p.s_m; });
  const size_t i = it == t.points.begin() ? 0 : static_cast<size_t>(it - t.points.begin()) - 1;
  const TrackPoint &a = t.points[i];
  const TrackPoint &b = (i + 1 < t.points.size()) ? t.points[i + 1] : t.points.front();
  const double b_s = (i + 1 < t.points.size()) ? b.s_m : t.length_m;
  const double u = b_s > a.s_m ? (s - a.s_m) / (b_s - a.s_m) : 0.0;
  return {a.x_m + u * (b.x_m - a.x_m), a.y_m + u * (b.y_m - a.y_m), a.heading_rad, s};
}

Projection project(const Track &t, double x, double y, double s_hint, double back_m,
                   double ahead_m) {
  const size_t n = t.points.size();
  Projection best;
  best.dist_m = 1e18;
  const size_t segs = t.loop ? n : n - 1;
  for (size_t i = 0; i < segs; ++i) {
    const TrackPoint &a = t.points[i], &b = t.points[(i + 1) % n];
    if (s_hint >= 0) {
      double ds = a.s_m - s_hint;
      if (t.loop) ds = std::remainder(ds, t.length_m);
      if (ds < -back_m - 0.1 || ds > ahead_m) continue;
    }
    const double dx = b.x_m - a.x_m, dy = b.y_m - a.y_m, len2 = dx * dx + dy * dy;
    const double u =
        len2 > 0 ? std::clamp(((x - a.x_m) * dx + (y - a.y_m) * dy) / len2, 0.0, 1.0) : 0.0;
    const double px = a.x_m + u * dx, py = a.y_m + u * dy;
    const double d = std::hypot(x - px, y - py);
    if (d < best.dist_m) {
      const double len = std::sqrt(len2);
      best.dist_m = d;
      best.s_m = a.s_m + u * len;
      if (t.loop && best.s_m >= t.length_m) best.s_m -= t.length_m;
      best.lateral_m = len > 0 ? (dx * (y - a.y_m) - dy * (x - a.x_m)) / len : 0.0;
    }
  }
  return best;
}

}  // namespace autodrive::behaviour
