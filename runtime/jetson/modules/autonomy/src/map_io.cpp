#include <autodrive/autonomy/map_io.hpp>

#include <autodrive/strict_yaml.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

namespace autodrive::autonomy {
namespace {

constexpr float kLoadedLogOdds = 5.0f;  // saturation used for loaded free/occupied cells

[[noreturn]] void map_fail(const std::string &file, const std::string &what) {
  throw std::runtime_error("map file '" + file + "': " + what);
}

// Next header token of a PGM, skipping whitespace and '#' comments.
std::string pgm_token(std::istream &in, const std::string &file) {
  std::string tok;
  int c;
  while ((c = in.get()) != EOF) {
    if (c == '#') {
      while ((c = in.get()) != EOF && c != '\n') {
      }
      continue;
    }
    if (std::isspace(c)) {
      if (!tok.empty()) return tok;
      continue;
    }
    tok.push_back(static_cast<char>(c));
  }
  if (tok.empty()) map_fail(file, "truncated PGM header");
  return tok;
}

int pgm_int(std::istream &in, const std::string &file, const char *what) {
  const std::string t = pgm_token(in, file);
  try {
    size_t used = 0;
    const int v = std::stoi(t, &used);
    if (used != t.size() || v <= 0) throw std::invalid_argument(t);
    return v;
  } catch (const std::exception &) {
    map_fail(file, std::string("bad PGM ") + what + " '" + t + "'");
  }
}

}  // namespace

void map_save(const GridMap &map, const std::string &yaml_path) {
  namespace fs = std::filesystem;
  const fs::path yp(yaml_path);
  fs::path pgm = yp;
  pgm.replace_extension(".pgm");
  {
    std::ofstream out(pgm, std::ios::binary);
    if (!out) map_fail(pgm.string(), "cannot open for writing");
    out << "P5\n# autodrive autonomy map, " << map.resolution_m << " m/cell\n"
        << map.width_cells << " " << map.height_cells << "\n255\n";
    std::string row(static_cast<size_t>(map.width_cells), '\0');
    for (int cy = map.height_cells - 1; cy >= 0; --cy) {  // PGM top row = max y
      for (int cx = 0; cx < map.width_cells; ++cx) {
        const CellState s = map.state(cx, cy);
        row[cx] = static_cast<char>(s == CellState::kFree       ? 254
                                    : s == CellState::kOccupied ? 0
                                                                : 205);
      }
      out.write(row.data(), static_cast<std::streamsize>(row.size()));
    }
    if (!out) map_fail(pgm.string(), "write failed");
  }
  std::ofstream y(yp);
  if (!y) map_fail(yaml_path, "cannot open for writing");
  y.precision(9);
  y << "image: " << pgm.filename().string() << "\n"
    << "mode: trinary\n"
    << "resolution: " << map.resolution_m << "\n"
    << "origin: [" << map.origin_x_m << ", " << map.origin_y_m << ", 0.0]\n"
    << "negate: 0\n"
    << "occupied_thresh: " << map.occupied_thresh << "\n"
    << "free_thresh: " << map.free_thresh << "\n";
  if (!y) map_fail(yaml_path, "write failed");
}

GridMap map_load(const std::string &yaml_path) {
  namespace fs = std::filesystem;
  // The ROS map_server format (image, resolution, origin, negate, thresholds, mode).
  const autodrive::yaml::Section root(autodrive::yaml::load_file(yaml_path), "", yaml_path);
  const auto image = root.get<std::string>("image");
  const auto resolution = root.get<double>("resolution");
  const auto origin = root.get<std::vector<double>>("origin");
  const int negate = root.get<int>("negate", 0);
  const double occ_th = root.get<double>("occupied_thresh", 0.65);
  const double free_th = root.get<double>("free_thresh", 0.196);
  const std::string mode = root.get<std::string>("mode", "trinary");
  root.reject_unknown();
  if (!(resolution > 0.0) || !std::isfinite(resolution))
    map_fail(yaml_path, "resolution must be a positive number of metres");
  if (origin.size() != 3) map_fail(yaml_path, "origin must be [x_m, y_m, yaw_rad]");
  if (std::abs(origin[2]) > 1e-9)
    map_fail(yaml_path, "rotated origins (yaw != 0) are not supported");
  if (!(free_th >= 0.0 && free_th < occ_th && occ_th <= 1.0))
    map_fail(yaml_path, "thresholds must satisfy 0 <= free_thresh < occupied_thresh <= 1");
  if (mode != "trinary" && mode != "scale")
    map_fail(yaml_path, "mode '" + mode + "' not supported (trinary or scale)");

  fs::path pgm(image);
  if (pgm.is_relative()) pgm = fs::path(yaml_path).parent_path() / pgm;
  const std::string pf = pgm.string();
  std::ifstream in(pgm, std::ios::binary);
  if (!in) map_fail(pf, "cannot be opened (named by " + yaml_path + ")");
  const std::string magic = pgm_token(in, pf);
  if (magic != "P5" && magic != "P2")
    map_fail(pf, "not a PGM (magic '" + magic + "', want P5 or P2)");
  const int w = pgm_int(in, pf, "width"), h = pgm_int(in, pf, "height");
  const int maxval = pgm_int(in, pf, "maxval");
  if (maxval > 255) map_fail(pf, "16-bit PGM not supported");
  // Checked before anything is allocated: a huge map is a clear error, not a bad_alloc.
  constexpr long long kMaxCells = 4096LL * 4096LL;
  if (static_cast<long long>(w) * h > kMaxCells)
    map_fail(pf, "width x height " + std::to_string(w) + " x " + std::to_string(h) + " = " +
                     std::to_string(static_cast<long long>(w) * h) + " cells exceeds " +
                     std::to_string(kMaxCells) + " (4096 x 4096)");

  GridMap map(w, h, resolution, origin[0], origin[1]);
  map.occupied_thresh = occ_th;
  map.free_thresh = free_th;
  std::vector<int> pix(static_cast<size_t>(w) * h);
  if (magic == "P5") {
    std::string buf(pix.size(), '\0');
    in.read(buf.data(), static_cast<std::streamsize>(buf.size()));
    if (in.gcount() != static_cast<std::streamsize>(buf.size()))
      map_fail(pf, "truncated pixel data (" + std::to_string(in.gcount()) + " of " +
                       std::to_string(buf.size()) + " bytes)");
    for (size_t i = 0; i < pix.size(); ++i) pix[i] = static_cast<unsigned char>(buf[i]);
  } else {
    for (auto &p : pix) {
      if (!(in >> p)) map_fail(pf, "truncated or non-numeric pixel data");
    }
  }
  for (int r = 0; r < h; ++r) {
    for (int cx = 0; cx < w; ++cx) {
      const int v = pix[static_cast<size_t>(r) * w + cx];
      if (v > maxval) map_fail(pf, "pixel value above maxval");
      double p = static_cast<double>(v) / maxval;
      if (!negate) p = 1.0 - p;  // dark = occupied
      float l = 0.0f;
      if (p > occ_th)
        l = kLoadedLogOdds;
      else if (p < free_th)
        l = -kLoadedLogOdds;
      else if (mode == "scale")
        l = static_cast<float>(std::log(p / (1.0 - p)));
      map.log_odds[map.index(cx, h - 1 - r)] = l;
    }
  }
  return map;
}

}  // namespace autodrive::autonomy
