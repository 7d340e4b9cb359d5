// Missing or malformed calibration and config files are rejected with the file and the field.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "eye_config.hpp"
#include "eye_error.hpp"
#include "eye_mapcal.hpp"

namespace {

std::string write_tmp(const std::string &name, const std::string &text) {
  const std::string p = testing::TempDir() + name;
  std::ofstream(p) << text;
  return p;
}

// Runs f, which must throw eye::Error mentioning every string in `must`.
template <class F>
void expect_error(F f, std::initializer_list<std::string> must) {
  try {
    f();
    ADD_FAILURE() << "no error";
  } catch (const eye::Error &e) {
    for (const auto &m : must)
      EXPECT_NE(std::string(e.what()).find(m), std::string::npos)
          << "'" << m << "' not in: " << e.what();
  }
}

const char *kGoodCamera =
    "width_px: 640\nheight_px: 480\nk: [500, 0, 319.5, 0, 500, 239.5, 0, 0, 1]\n"
    "dist: [0, 0, 0, 0, 0]\n";
const char *kGoodMap =
    "width_px: 640\nheight_px: 480\nr_cam_map: [1, 0, 0, 0, -1, 0, 0, 0, -1]\n"
    "t_cam_map_m: [-1.5, 1.0, 2.5]\n";

}  // namespace

TEST(BadFiles, Intrinsics) {
  expect_error([] { eye::intrinsics_load("/nonexistent/camera.yaml"); },
               {"/nonexistent/camera.yaml", "cannot be opened"});
  const auto notyaml = write_tmp("eye_bad_notyaml.yaml", "k: [1, 2\n");
  expect_error([&] { eye::intrinsics_load(notyaml); }, {notyaml, "not valid YAML"});
  const auto nok =
      write_tmp("eye_bad_nok.yaml", "width_px: 640\nheight_px: 480\ndist: [0,0,0,0]\n");
  expect_error([&] { eye::intrinsics_load(nok); }, {nok, "k: missing key"});
  const auto shortk =
      write_tmp("eye_bad_shortk.yaml",
                "width_px: 640\nheight_px: 480\nk: [1, 0, 0, 0, 1, 0, 0, 0]\ndist: [0,0,0,0]\n");
  expect_error([&] { eye::intrinsics_load(shortk); }, {shortk, "k: ", "9 numbers"});
  const auto textk =
      write_tmp("eye_bad_textk.yaml",
                "width_px: 640\nheight_px: 480\nk: [a, 0, 0, 0, 1, 0, 0, 0, 1]\ndist: [0,0,0,0]\n");
  expect_error([&] { eye::intrinsics_load(textk); }, {textk, "k: "});
  const auto negf = write_tmp(
      "eye_bad_negf.yaml",
      "width_px: 640\nheight_px: 480\nk: [-5, 0, 0, 0, 1, 0, 0, 0, 1]\ndist: [0,0,0,0]\n");
  expect_error([&] { eye::intrinsics_load(negf); }, {negf, "k: ", "camera matrix"});
  const auto dist3 =
      write_tmp("eye_bad_dist.yaml",
                "width_px: 640\nheight_px: 480\nk: [5, 0, 0, 0, 5, 0, 0, 0, 1]\ndist: [0,0,0]\n");
  expect_error([&] { eye::intrinsics_load(dist3); }, {dist3, "dist: "});
  const auto w = write_tmp(
      "eye_bad_w.yaml",
      "width_px: wide\nheight_px: 480\nk: [5, 0, 0, 0, 5, 0, 0, 0, 1]\ndist: [0,0,0,0]\n");
  expect_error([&] { eye::intrinsics_load(w); }, {w, "width_px: "});
}

TEST(BadFiles, MapCalibration) {
  const auto nor =
      write_tmp("eye_bad_map_nor.yaml", "width_px: 640\nheight_px: 480\nt_cam_map_m: [0, 0, 1]\n");
  expect_error([&] { eye::mapcal_load(nor); }, {nor, "r_cam_map: "});
  const auto notrot =
      write_tmp("eye_bad_map_rot.yaml",
                "width_px: 640\nheight_px: 480\nr_cam_map: [2, 0, 0, 0, 1, 0, 0, 0, 1]\n"
                "t_cam_map_m: [0, 0, 1]\n");
  expect_error([&] { eye::mapcal_load(notrot); }, {notrot, "r_cam_map: ", "not a rotation"});
  const auto t2 =
      write_tmp("eye_bad_map_t.yaml",
                "width_px: 640\nheight_px: 480\nr_cam_map: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
                "t_cam_map_m: [0, 1]\n");
  expect_error([&] { eye::mapcal_load(t2); }, {t2, "t_cam_map_m: "});
}

TEST(BadFiles, ReferenceTags) {
  const auto none = write_tmp("eye_bad_tags_none.yaml", "tags: []\n");
  expect_error([&] { eye::reftags_load(none); }, {none, "tags: "});
  const auto dup = write_tmp("eye_bad_tags_dup.yaml",
                             "tags:\n - {id: 3, x_m: 0, y_m: 0, size_m: 0.1}\n"
                             " - {id: 3, x_m: 1, y_m: 0, size_m: 0.1}\n");
  expect_error([&] { eye::reftags_load(dup); }, {dup, "tags[1]", "listed twice"});
  const auto nosize = write_tmp("eye_bad_tags_size.yaml", "tags:\n - {id: 3, x_m: 0, y_m: 0}\n");
  expect_error([&] { eye::reftags_load(nosize); }, {nosize, "tags[0]", "size_m: "});
  const auto badid =
      write_tmp("eye_bad_tags_id.yaml", "tags:\n - {id: 900, x_m: 0, y_m: 0, size_m: 0.1}\n");
  expect_error([&] { eye::reftags_load(badid); }, {badid, "id: "});
}

TEST(BadFiles, RunConfig) {
  write_tmp("eye_cfg_camera.yaml", kGoodCamera);
  write_tmp("eye_cfg_map.yaml", kGoodMap);
  const std::string head =
      "intrinsics: eye_cfg_camera.yaml\nmap: eye_cfg_map.yaml\ntag_size_m: 0.1\n"
      "tag_offset_m: [0.035125, 0, 0.129165]\n";
  const auto good =
      write_tmp("eye_cfg_good.yaml", head + "vehicles:\n - {name: NIGEL1, tag_id: 1}\n");
  const eye::RunConfig c = eye::runconfig_load(good);
  EXPECT_EQ(c.vehicles.size(), 1u);
  EXPECT_EQ(c.in.width_px, 640);

  const auto nov = write_tmp("eye_cfg_nov.yaml", head);
  expect_error([&] { eye::runconfig_load(nov); }, {nov, "vehicles: "});
  const auto dupid = write_tmp(
      "eye_cfg_dup.yaml", head + "vehicles:\n - {name: A, tag_id: 1}\n - {name: B, tag_id: 1}\n");
  expect_error([&] { eye::runconfig_load(dupid); }, {dupid, "vehicles[1]", "tag_id: "});
  const auto off =
      write_tmp("eye_cfg_off.yaml",
                "intrinsics: eye_cfg_camera.yaml\nmap: eye_cfg_map.yaml\ntag_size_m: 0.1\n"
                "tag_offset_m: [0.03, 0]\nvehicles:\n - {name: A, tag_id: 1}\n");
  expect_error([&] { eye::runconfig_load(off); }, {off, "tag_offset_m: "});
  const auto missing_cam =
      write_tmp("eye_cfg_nocam.yaml",
                "intrinsics: no_such_camera.yaml\nmap: eye_cfg_map.yaml\ntag_size_m: 0.1\n"
                "tag_offset_m: [0.03, 0, 0.1]\nvehicles:\n - {name: A, tag_id: 1}\n");
  expect_error([&] { eye::runconfig_load(missing_cam); },
               {"no_such_camera.yaml", "cannot be opened"});
  // calibration files of different cameras
  write_tmp("eye_cfg_map720.yaml",
            "width_px: 1280\nheight_px: 720\nr_cam_map: [1, 0, 0, 0, -1, 0, 0, 0, "
            "-1]\nt_cam_map_m: [0, 0, 2]\n");
  const auto mismatch =
      write_tmp("eye_cfg_mismatch.yaml",
                "intrinsics: eye_cfg_camera.yaml\nmap: eye_cfg_map720.yaml\ntag_size_m: 0.1\n"
                "tag_offset_m: [0.03, 0, 0.1]\nvehicles:\n - {name: A, tag_id: 1}\n");
  expect_error([&] { eye::runconfig_load(mismatch); }, {"eye_cfg_map720.yaml", "differs"});
  // Every number has a range: refused naming the key and the bound.
  const auto veh = std::string("vehicles:\n - {name: A, tag_id: 1}\n");
  const auto dec = write_tmp("eye_cfg_dec.yaml", head + "detector: {decimate: 100}\n" + veh);
  expect_error([&] { eye::runconfig_load(dec); },
               {dec, "detector.decimate: 100 is out of range: must be 1..8"});
  const auto ham = write_tmp("eye_cfg_ham.yaml", head + "detector: {max_hamming: -1}\n" + veh);
  expect_error([&] { eye::runconfig_load(ham); },
               {ham, "detector.max_hamming: -1 is out of range"});
  const auto big = write_tmp("eye_cfg_big.yaml",
                             "intrinsics: eye_cfg_camera.yaml\nmap: eye_cfg_map.yaml\n"
                             "tag_size_m: 50\n" +
                                 veh);
  expect_error([&] { eye::runconfig_load(big); }, {big, "tag_size_m: 50 is out of range"});
}
