#include <autodrive/autonomy/reeds_shepp.hpp>

#include <algorithm>
#include <cmath>

namespace autodrive::autonomy {
namespace {

// Normalised lengths: arcs in radians, straights in turning radii.
struct Word {
  char types[5];
  double len[5];
  int n;
};

double mod2pi(double a) {
  return angle_wrap_rad(a);
}
void polar(double x, double y, double &r, double &th) {
  r = std::hypot(x, y);
  th = std::atan2(y, x);
}

bool LpSpLp(double x, double y, double phi, double &t, double &u, double &v) {
  polar(x - std::sin(phi), y - 1.0 + std::cos(phi), u, t);
  if (t < 0) return false;
  v = mod2pi(phi - t);
  return v >= 0;
}
bool LpSpRp(double x, double y, double phi, double &t, double &u, double &v) {
  double u1, t1;
  polar(x + std::sin(phi), y - 1.0 - std::cos(phi), u1, t1);
  u1 = u1 * u1;
  if (u1 < 4.0) return false;
  u = std::sqrt(u1 - 4.0);
  const double theta = std::atan2(2.0, u);
  t = mod2pi(t1 + theta);
  v = mod2pi(t - phi);
  return t >= 0 && v >= 0;
}
bool LpRmL(double x, double y, double phi, double &t, double &u, double &v) {
  const double xi = x - std::sin(phi), eta = y - 1.0 + std::cos(phi);
  double u1, theta;
  polar(xi, eta, u1, theta);
  if (u1 > 4.0) return false;
  u = -2.0 * std::asin(0.25 * u1);
  t = mod2pi(theta + 0.5 * u + kPi);
  v = mod2pi(phi - t + u);
  return t >= 0 && u <= 0;
}
void tau_omega(double u, double v, double xi, double eta, double phi, double &tau, double &omega) {
  const double delta = mod2pi(u - v);
  const double A = std::sin(u) - std::sin(delta), B = std::cos(u) - std::cos(delta) - 1.0;
  const double t1 = std::atan2(eta * A - xi * B, xi * A + eta * B);
  const double t2 = 2.0 * (std::cos(delta) - std::cos(v) - std::cos(u)) + 3.0;
  tau = t2 < 0 ? mod2pi(t1 + kPi) : mod2pi(t1);
  omega = mod2pi(tau - u + v - phi);
}
bool LpRupLumRm(double x, double y, double phi, double &t, double &u, double &v) {
  const double xi = x + std::sin(phi), eta = y - 1.0 - std::cos(phi);
  const double rho = 0.25 * (2.0 + std::hypot(xi, eta));
  if (rho > 1.0) return false;
  u = std::acos(rho);
  tau_omega(u, -u, xi, eta, phi, t, v);
  return t >= 0 && v <= 0;
}
bool LpRumLumRp(double x, double y, double phi, double &t, double &u, double &v) {
  const double xi = x + std::sin(phi), eta = y - 1.0 - std::cos(phi);
  const double rho = (20.0 - xi * xi - eta * eta) / 16.0;
  if (rho < 0 || rho > 1) return false;
  u = -std::acos(rho);
  if (u < -kPi / 2) return false;
  tau_omega(u, u, xi, eta, phi, t, v);
  return t >= 0 && v >= 0;
}
bool LpRmSmLm(double x, double y, double phi, double &t, double &u, double &v) {
  const double xi = x - std::sin(phi), eta = y - 1.0 + std::cos(phi);
  double rho, theta;
  polar(xi, eta, rho, theta);
  if (rho < 2.0) return false;
  const double r = std::sqrt(rho * rho - 4.0);
  u = 2.0 - r;
  t = mod2pi(theta + std::atan2(r, -2.0));
  v = mod2pi(phi - kPi / 2 - t);
  return t >= 0 && u <= 0 && v <= 0;
}
bool LpRmSmRm(double x, double y, double phi, double &t, double &u, double &v) {
  const double xi = x + std::sin(phi), eta = y - 1.0 - std::cos(phi);
  double rho, theta;
  polar(-eta, xi, rho, theta);
  if (rho < 2.0) return false;
  t = theta;
  u = 2.0 - rho;
  v = mod2pi(t + kPi / 2 - phi);
  return t >= 0 && u <= 0 && v <= 0;
}
bool LpRmSLmRp(double x, double y, double phi, double &t, double &u, double &v) {
  const double xi = x + std::sin(phi), eta = y - 1.0 - std::cos(phi);
  double rho, theta;
  polar(xi, eta, rho, theta);
  if (rho < 2.0) return false;
  u = 4.0 - std::sqrt(rho * rho - 4.0);
  if (u > 0) return false;
  t = mod2pi(std::atan2((4.0 - u) * xi - 2.0 * eta, -2.0 * xi + (u - 4.0) * eta));
  v = mod2pi(t - phi);
  return t >= 0 && v >= 0;
}

using Family = bool (*)(double, double, double, double &, double &, double &);

// Adds the four time-flip / reflect variants of a family. lens maps (t,u,v) to the word's
// segment lengths; types is the word in the base (unreflected) form.
// Fixed-capacity word list (no heap: the planner calls this for every node).
struct Words {
  Word w[64];
  int n = 0;
  void push_back(const Word &x) {
    if (n < 64) w[n++] = x;
  }
};

template <typename LenFn>
void add_variants(Words &out, Family f, const char *types, int n, double x, double y, double phi,
                  LenFn lens) {
  for (int flip = 0; flip < 2; ++flip) {
    for (int refl = 0; refl < 2; ++refl) {
      const double xx = flip ? -x : x, yy = refl ? -y : y, pp = (flip ^ refl) ? -phi : phi;
      double t, u, v;
      if (!f(xx, yy, pp, t, u, v)) continue;
      Word w{};
      w.n = n;
      double l[5];
      lens(t, u, v, l);
      for (int i = 0; i < n; ++i) {
        char c = types[i];
        if (refl && c != 'S') c = c == 'L' ? 'R' : 'L';
        w.types[i] = c;
        w.len[i] = flip ? -l[i] : l[i];
      }
      out.push_back(w);
    }
  }
}

Words rs_words(double x, double y, double phi) {
  Words w;
  auto tuv = [](double t, double u, double v, double *l) {
    l[0] = t;
    l[1] = u;
    l[2] = v;
  };
  auto vut = [](double t, double u, double v, double *l) {
    l[0] = v;
    l[1] = u;
    l[2] = t;
  };
  add_variants(w, LpSpLp, "LSL", 3, x, y, phi, tuv);
  add_variants(w, LpSpRp, "LSR", 3, x, y, phi, tuv);
  add_variants(w, LpRmL, "LRL", 3, x, y, phi, tuv);
  // CCC backwards: solve in the goal's frame, read the word in reverse order.
  const double xb = x * std::cos(phi) + y * std::sin(phi),
               yb = x * std::sin(phi) - y * std::cos(phi);
  add_variants(w, LpRmL, "LRL", 3, xb, yb, phi, vut);
  add_variants(w, LpRupLumRm, "LRLR", 4, x, y, phi, [](double t, double u, double v, double *l) {
    l[0] = t;
    l[1] = u;
    l[2] = -u;
    l[3] = v;
  });
  add_variants(w, LpRumLumRp, "LRLR", 4, x, y, phi, [](double t, double u, double v, double *l) {
    l[0] = t;
    l[1] = u;
    l[2] = u;
    l[3] = v;
  });
  auto ccsc = [](double t, double u, double v, double *l) {
    l[0] = t;
    l[1] = -kPi / 2;
    l[2] = u;
    l[3] = v;
  };
  auto cscc = [](double t, double u, double v, double *l) {
    l[0] = v;
    l[1] = u;
    l[2] = -kPi / 2;
    l[3] = t;
  };
  add_variants(w, LpRmSmLm, "LRSL", 4, x, y, phi, ccsc);
  add_variants(w, LpRmSmRm, "LRSR", 4, x, y, phi, ccsc);
  add_variants(w, LpRmSmLm, "LSRL", 4, xb, yb, phi, cscc);
  add_variants(w, LpRmSmRm, "RSRL", 4, xb, yb, phi, cscc);
  add_variants(w, LpRmSLmRp, "LRSLR", 5, x, y, phi, [](double t, double u, double v, double *l) {
    l[0] = t;
    l[1] = -kPi / 2;
    l[2] = u;
    l[3] = -kPi / 2;
    l[4] = v;
  });
  return w;
}

}  // namespace

double RsPath::length_m() const {
  double s = 0;
  for (const auto &g : segments) s += std::abs(g.length_m);
  return s;
}

Path rs_sample(const Pose2 &start, const RsPath &path, double R, double step_m) {
  Path out;
  Pose2 p = start;
  for (const auto &g : path.segments) {
    if (std::abs(g.length_m) < 1e-9) continue;
    const double k = g.type == 'L' ? 1.0 / R : g.type == 'R' ? -1.0 / R : 0.0;
    const int dir = g.length_m >= 0 ? 1 : -1;
    const int n = std::max(1, static_cast<int>(std::ceil(std::abs(g.length_m) / step_m)));
    const double ds = g.length_m / n;
    for (int i = 0; i < n; ++i) {
      out.push_back({p, dir, k});
      p = arc_step(p, ds, k);
    }
  }
  const int last_dir = out.empty() ? 1 : out.back().direction;
  out.push_back({p, last_dir, 0.0});
  return out;
}

namespace {

// True when the word, integrated, really ends at rel (normalised units).
bool word_reaches(const Word &w, double x, double y, double phi) {
  Pose2 e{0, 0, 0};
  for (int i = 0; i < w.n; ++i) {
    const double k = w.types[i] == 'L' ? 1.0 : w.types[i] == 'R' ? -1.0 : 0.0;
    e = arc_step(e, w.len[i], k);
  }
  return std::hypot(e.x_m - x, e.y_m - y) < 1e-7 &&
         std::abs(angle_wrap_rad(e.yaw_rad - phi)) < 1e-7;
}

double word_length(const Word &w) {
  double s = 0;
  for (int i = 0; i < w.n; ++i) s += std::abs(w.len[i]);
  return s;
}

}  // namespace

double rs_shortest_length_m(const Pose2 &start, const Pose2 &goal, double R) {
  const Pose2 rel = pose_between(start, goal);
  const double x = rel.x_m / R, y = rel.y_m / R, phi = rel.yaw_rad;
  const Words ws = rs_words(x, y, phi);
  double best = -1.0;
  for (int i = 0; i < ws.n; ++i) {
    const double l = word_length(ws.w[i]);
    if ((best < 0 || l < best) && word_reaches(ws.w[i], x, y, phi)) best = l;
  }
  return best < 0 ? -1.0 : best * R;
}

std::vector<RsPath> rs_paths(const Pose2 &start, const Pose2 &goal, double R) {
  const Pose2 rel = pose_between(start, goal);
  const double x = rel.x_m / R, y = rel.y_m / R, phi = rel.yaw_rad;
  std::vector<RsPath> out;
  const Words ws = rs_words(x, y, phi);
  for (int k = 0; k < ws.n; ++k) {
    const Word &w = ws.w[k];
    if (!word_reaches(w, x, y, phi)) continue;  // a candidate must really end at the goal
    RsPath p;
    for (int i = 0; i < w.n; ++i) p.segments.push_back({w.types[i], w.len[i] * R});
    out.push_back(p);
  }
  std::sort(out.begin(), out.end(),
            [](const RsPath &a, const RsPath &b) { return a.length_m() < b.length_m(); });
  return out;
}

}  // namespace autodrive::autonomy
