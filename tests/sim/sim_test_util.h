// Helpers shared by the simulator tests: temp dirs and a sim built from the repo's files.
#pragma once
#include <stdlib.h>
#include <unistd.h>

#include <string>

#include "sim.h"

namespace simtest {

inline std::string temp_dir() {
  char tmpl[] = "/tmp/sim-test-XXXXXX";
  const char *d = mkdtemp(tmpl);
  return d ? std::string(d) : std::string();
}

inline std::string params_path() {
  return std::string(SIM_DIR) + "/../../vehicle/nigel.params";
}
// A map name from maps/, or a path (with '/') as is.
inline std::string map_path(const char *name) {
  if (std::string(name).find('/') != std::string::npos) return name;
  return std::string(MAPS_DIR) + "/" + name + ".xml";
}
inline std::string fixture(const char *file) {
  return std::string(SIM_TEST_DIR) + "/fixtures/" + file;
}

// A sim with the default parameters on the parking school, no ptys, optional script.
struct Sim {
  sim_t *s = nullptr;
  std::string run_dir, err;
  explicit Sim(const char *script, int cars = 1, int ptys = 0, int tyre_model = -1,
               const char *map = "parking_school", int lidar = 0, uint64_t seed = 3) {
    run_dir = temp_dir();
    const std::string params = params_path(), mp = map_path(map);
    sim_config_t cfg = {};
    cfg.params_path = params.c_str();
    cfg.map_path = mp.c_str();
    cfg.run_dir = run_dir.c_str();
    cfg.cars = cars;
    cfg.seed = seed;
    cfg.open_ptys = ptys;
    cfg.script = script;
    cfg.lidar = lidar;
    cfg.tyre_model = tyre_model;
    char e[2048] = "";
    s = sim_create(&cfg, e, sizeof e);
    err = e;
  }
  ~Sim() {
    sim_destroy(s);
    rmdir(run_dir.c_str());
  }
  // Steps until sim time t_s; returns false on a sim error.
  bool run_to(double t_s) {
    char e[512];
    while (sim_time_us(s) < (int64_t)(t_s * 1e6 + 0.5))
      if (sim_step(s, e, sizeof e) != 0) {
        err = e;
        return false;
      }
    return true;
  }
  sim_truth_t truth(int car = 1) const {
    sim_truth_t t;
    sim_get_truth(s, car, &t);
    return t;
  }
};

}  // namespace simtest
