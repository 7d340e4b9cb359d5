// The one "next light and sign ahead" (common/road_rules) against the city driver's tracks on the
// real sidecar JSONs: on every pose (2 cm apart) of every route, the light the road network's
// walk finds ahead (what the SCM and its stand-in advise, through the same library) is the
// next light stop of the city driver's track, at the same distance.
#include <gtest/gtest.h>

#include <autodrive/behaviour/city_map.hpp>
#include <autodrive/road_rules.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

using namespace autodrive::behaviour;

namespace {

const std::string kMaps = std::string(AUTODRIVE_ROOT) + "/maps/";

// The city driver's next light stop at or after base_link s_m (within horizon_m): id, distance.
std::pair<int, double> track_next_light(const Track &t, double s_m, double horizon_m) {
  for (int lap = 0; lap < (t.loop ? 2 : 1); ++lap)
    for (const Stop &st : t.stops) {
      const double d = st.s_m + lap * t.length_m - s_m;
      if (st.kind != Stop::Kind::light || d < 0) continue;
      if (d > horizon_m) return {-1, -1.0};
      return {st.light_id, d};
    }
  return {-1, -1.0};
}

struct Agreement {
  int poses = 0, with_light = 0;
};

void check_route(const CityMap &m, const std::string &route, Agreement &a) {
  const Track t = track_for(m, route);
  const auto idx = std::find(m.route_order.begin(), m.route_order.end(), route);
  const int r = static_cast<int>(idx - m.route_order.begin());
  int last = -1;
  const double end = t.loop ? t.length_m : t.points.back().s_m;
  for (double s = 0; s < end; s += 0.02) {
    const TrackPoint p = point_at(t, s);
    const double yaw = p.heading_rad;
    road_place_t place{};
    ASSERT_TRUE(m.roads->place(p.x_m, p.y_m, yaw, r, last, place)) << route << " s=" << s;
    last = place.lane;
    const road_ahead_t ahead = m.roads->ahead(place, r);
    const auto [id, d] = track_next_light(t, s, ROAD_HORIZON_M);
    // a pose right at a stop line or at the horizon's edge may fall either way
    if (id >= 0 && (d < 1e-3 || d > ROAD_HORIZON_M - 1e-3)) continue;
    ++a.poses;
    EXPECT_EQ(ahead.light_id, id) << route << " s=" << s << " lane " << m.lane_order[last];
    if (id >= 0 && ahead.light_id == id) {
      ++a.with_light;
      EXPECT_NEAR(ahead.stop_line_distance_m, d, 1e-6) << route << " s=" << s;
    }
  }
}

}  // namespace

TEST(RoadRules, WalkAheadAgreesWithTheCityDriversTracks) {
  for (const char *name : {"tiny_town", "intersection_school", "driving_school"}) {
    const CityMap m = load_city_map(kMaps + name + ".json");
    for (const std::string &route : m.route_order) {
      Agreement a;
      ASSERT_NO_FATAL_FAILURE(check_route(m, route, a));
      EXPECT_GT(a.poses, 100) << name << " " << route;
      if (!m.lights.empty() && route.find("loop") == std::string::npos) {
        EXPECT_GT(a.with_light, 0) << name << " " << route << ": no light ahead anywhere";
      }
    }
  }
}

// A light governs every lane of its approach: the turn west from the north approach stops at
// light 1 too (the city driver once put lights only on their own lane).
TEST(RoadRules, ALightGovernsEveryLaneOfItsApproach) {
  const CityMap m = load_city_map(kMaps + "tiny_town.json");
  const Track t = track_for(m, "north_to_lot");
  const bool light1 = std::any_of(t.stops.begin(), t.stops.end(), [](const Stop &s) {
    return s.kind == Stop::Kind::light && s.light_id == 1;
  });
  EXPECT_TRUE(light1);
}

TEST(RoadRules, BadInputIsNamed) {
  using autodrive::road::LaneInput;
  using autodrive::road::Network;
  const LaneInput ok{{{0, 0, 0}, {1, 0, 0}}, 0.14};
  const LaneInput one_point{{{0, 0, 0}}, 0.14};
  try {
    Network({ok, one_point}, {}, {}, {});
    FAIL() << "a one-point lane was accepted";
  } catch (const std::invalid_argument &e) {
    EXPECT_NE(std::string(e.what()).find("lane 1"), std::string::npos) << e.what();
  }
  try {
    Network({ok}, {{7, 3, 0.5, 0.0}}, {}, {});
    FAIL() << "a light on a lane that does not exist was accepted";
  } catch (const std::invalid_argument &e) {
    EXPECT_NE(std::string(e.what()).find("light 7"), std::string::npos) << e.what();
  }
}

TEST(RoadRules, NoLaneNoPlaceAndAForkStopsTheWalk) {
  using autodrive::road::Network;
  // a straight lane forking into two; a light on the first, a sign on the left branch
  const Network n({{{{0, 0, 0}, {1, 0, 0}}, 0.14},
                   {{{1, 0, 0}, {2, 0, 0}}, 0.14},
                   {{{1, 0, 0}, {1.7, 0.7, 1.5708}}, 0.14}},
                  {{5, 0, 0.5, 0.0}}, {{9, 2, 1.2, 0.3, 0.0, -1.0}}, {{{0, 2}, false}});
  road_place_t p{};
  EXPECT_FALSE(n.place(0.5, 1.0, 0.0, -1, -1, p));  // 1 m off the lane
  ASSERT_TRUE(n.place(0.2, 0.01, 0.0, -1, -1, p));
  EXPECT_EQ(p.lane, 0);
  road_ahead_t a = n.ahead(p, -1);
  EXPECT_EQ(a.light_id, 5);
  EXPECT_NEAR(a.stop_line_distance_m, 0.3, 1e-9);
  EXPECT_EQ(a.sign_id, -1);  // beyond the fork: unknown without a route
  a = n.ahead(p, 0);         // along route 0 (the left branch)
  EXPECT_EQ(a.sign_id, 9);
}
