// Loads tests/sim_sensors/test_room.xml with real tag36h11 roof textures (ids below) written
// into a fresh temp dir. Shared by the sim_sensors tests.
#pragma once
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

extern "C" {
#include "sim_tags.h"
}

namespace room {

constexpr int kTagCar = 1;    // roof tag id of "car"
constexpr int kTagOther = 2;  // roof tag id of "other"

inline std::string replace(std::string s, const std::string &key, const std::string &val) {
  size_t p = s.find(key);
  if (p != std::string::npos) s.replace(p, key.size(), val);
  return s;
}

struct Room {
  mjModel *m = nullptr;
  mjData *d = nullptr;
  std::string dir;
  Room() {
    char tmpl[] = "/tmp/sim_sensors_test_XXXXXX";
    const char *dp = mkdtemp(tmpl);
    if (!dp) ADD_FAILURE() << "mkdtemp failed";
    dir = dp ? dp : "/tmp";
    std::ifstream in(std::string(SIM_SENSORS_TEST_DIR) + "/test_room.xml");
    std::stringstream ss;
    ss << in.rdbuf();
    std::string xml = ss.str();
    std::string assets;
    const char *names[2] = {"car_", "other_"};
    const int ids[2] = {kTagCar, kTagOther};
    const char *keys[2] = {"@TAG_CAR@", "@TAG_OTHER@"};
    for (int i = 0; i < 2; i++) {
      std::string png = dir + "/tag36h11_" + std::to_string(ids[i]) + ".png";
      char err[256];
      EXPECT_EQ(0, sim_tags_write_png(png.c_str(), ids[i], 8, err, sizeof err)) << err;
      char a[1024], g[1024];
      EXPECT_EQ(0, sim_tags_mjcf(names[i], png.c_str(), SIM_TAGS_SIZE_M, a, sizeof a, g, sizeof g));
      assets += a;
      xml = replace(xml, keys[i], g);
    }
    xml = replace(xml, "@ASSETS@", assets);
    std::string path = dir + "/room.xml";
    std::ofstream(path) << xml;
    char err[1000] = "";
    m = mj_loadXML(path.c_str(), nullptr, err, sizeof err);
    if (!m) ADD_FAILURE() << "mj_loadXML: " << err;
    if (m) {
      d = mj_makeData(m);
      mj_forward(m, d);
    }
  }
  ~Room() {
    if (d) mj_deleteData(d);
    if (m) mj_deleteModel(m);
    std::string cmd = "rm -rf '" + dir + "'";
    if (dir.rfind("/tmp/sim_sensors_test_", 0) == 0 && std::system(cmd.c_str()) != 0)
      std::fprintf(stderr, "could not remove %s\n", dir.c_str());
  }
};

}  // namespace room
