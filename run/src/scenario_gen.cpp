// The scenario generator (scenario_gen.h). A layout is a set of axis-aligned rooms on a 0.1 m
// grid (corridor pieces are rooms too); walls are the grid boundaries between different rooms
// or a room and the outside, minus the openings (doors, archways). Landmarks hang on wall
// faces or on furniture faces / tops along the route; furniture stands off the route; people
// walk on straight stretches of it. The sketch is the intended route and landmarks through a
// person's drawing errors.
#include "sketchnav/run/scenario_gen.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <random>
#include <set>

#include "sketchnav/core/error.h"
#include "sketchnav/core/paths.h"
#include "sketchnav/mapsketch/io.h"
#include "sketchnav/mapsketch/route.h"
#include "sketchnav/sim/world.h"
#include "sketchnav/sim/world_check.h"

namespace sketchnav::run {
namespace {

using V2 = Eigen::Vector2d;
constexpr double kDeg = M_PI / 180.0;
constexpr double kRes = 0.1;     // [m] layout grid
constexpr double kWallT = 0.10;  // [m] wall thickness (faces 5 cm off the grid line)

const std::vector<std::string> kFamilies = {"corridor", "hall", "office", "mixed"};
const std::vector<std::string> kKinds = {
    "rotation",          "anisotropic_scale", "distance_bias",  "corners_misplaced",
    "corner_wrong_side", "landmark_missing",  "landmark_moved", "start_heading"};

// Seeded draws with fixed arithmetic (std:: distributions differ between libraries).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : g_(seed) {}
  double uniform(double a = 0, double b = 1) {
    return a + (b - a) * (static_cast<double>(g_() >> 11) * 0x1.0p-53);
  }
  int integer(int a, int b) {  // [a, b]
    return a + static_cast<int>(g_() % static_cast<std::uint64_t>(b - a + 1));
  }
  bool chance(double p) { return uniform() < p; }
  double normal() {
    const double u1 = std::max(uniform(), 1e-300), u2 = uniform();
    return std::sqrt(-2 * std::log(u1)) * std::cos(2 * M_PI * u2);
  }
  double clippedNormal(double sigma, double clip) {
    return std::clamp(sigma * normal(), -clip, clip);
  }
  template <class T>
  const T& pick(const std::vector<T>& v) {
    return v[static_cast<size_t>(integer(0, static_cast<int>(v.size()) - 1))];
  }

 private:
  std::mt19937_64 g_;
};

// An error of size in [lo, hi] either way: an applied error is never negligibly small.
double signedMagnitude(Rng& rng, double lo, double hi) {
  const double m = rng.uniform(lo, hi);
  return rng.chance(0.5) ? m : -m;
}

double snap(double x) {
  return std::round(x / kRes) * kRes;
}
double round2(double x) {
  return std::round(x * 100) / 100;
}
Json j2(const V2& p) {
  return Json::array({round2(p.x()), round2(p.y())});
}
V2 rot(const V2& v, double a) {
  return {std::cos(a) * v.x() - std::sin(a) * v.y(), std::sin(a) * v.x() + std::cos(a) * v.y()};
}

double segDist(const V2& p, const V2& a, const V2& b) {
  const V2 d = b - a;
  const double l2 = d.squaredNorm();
  const double t = l2 > 0 ? std::clamp((p - a).dot(d) / l2, 0.0, 1.0) : 0.0;
  return (a + t * d - p).norm();
}
double polyDist(const V2& p, const std::vector<V2>& poly) {
  double best = 1e300;
  for (size_t i = 0; i + 1 < poly.size(); ++i)
    best = std::min(best, segDist(p, poly[i], poly[i + 1]));
  return best;
}
double polyLength(const std::vector<V2>& poly) {
  double s = 0;
  for (size_t i = 0; i + 1 < poly.size(); ++i) s += (poly[i + 1] - poly[i]).norm();
  return s;
}
// Point and unit direction at arc length s along the polyline.
std::pair<V2, V2> along(const std::vector<V2>& poly, double s) {
  for (size_t i = 0; i + 1 < poly.size(); ++i) {
    const V2 d = poly[i + 1] - poly[i];
    const double L = d.norm();
    if (s <= L || i + 2 == poly.size()) return {poly[i] + d / L * std::clamp(s, 0.0, L), d / L};
    s -= L;
  }
  return {poly.back(), V2(1, 0)};
}

struct Rect {
  double x0, y0, x1, y1;
};
struct Opening {
  V2 a, b;  // on a grid line, axis-aligned
  bool door = false;
  bool open = true;
  std::string name;
};

// ---------------------------------------------------------------- layout grid
class Layout {
 public:
  std::vector<std::pair<Rect, int>> rooms;  // id >= 1; later rooms overwrite earlier ones
  std::map<int, std::string> room_names;
  std::vector<Opening> openings;
  std::vector<V2> route;

  void rasterise() {
    double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
    for (const auto& [r, id] : rooms) {
      x0 = std::min(x0, r.x0), y0 = std::min(y0, r.y0);
      x1 = std::max(x1, r.x1), y1 = std::max(y1, r.y1);
    }
    ox_ = snap(x0) - 2 * kRes;
    oy_ = snap(y0) - 2 * kRes;
    nx_ = static_cast<int>(std::lround((snap(x1) - ox_) / kRes)) + 2;
    ny_ = static_cast<int>(std::lround((snap(y1) - oy_) / kRes)) + 2;
    id_.assign(static_cast<size_t>(nx_) * ny_, 0);
    occ_.assign(id_.size(), 0);
    for (const auto& [r, id] : rooms)
      for (int j = 0; j < ny_; ++j)
        for (int i = 0; i < nx_; ++i) {
          const V2 c = centre(i, j);
          if (c.x() > r.x0 && c.x() < r.x1 && c.y() > r.y0 && c.y() < r.y1) at(i, j) = id;
        }
    floor_ = {{ox_ + kRes, oy_ + kRes},
              {ox_ + (nx_ - 1) * kRes, oy_ + kRes},
              {ox_ + (nx_ - 1) * kRes, oy_ + (ny_ - 1) * kRes},
              {ox_ + kRes, oy_ + (ny_ - 1) * kRes}};
  }
  const std::vector<V2>& floor() const { return floor_; }
  V2 centre(int i, int j) const { return {ox_ + (i + 0.5) * kRes, oy_ + (j + 0.5) * kRes}; }
  int& at(int i, int j) { return id_[static_cast<size_t>(j) * nx_ + i]; }
  int idAt(const V2& p) const {
    const int i = static_cast<int>(std::floor((p.x() - ox_) / kRes));
    const int j = static_cast<int>(std::floor((p.y() - oy_) / kRes));
    if (i < 0 || j < 0 || i >= nx_ || j >= ny_) return 0;
    return id_[static_cast<size_t>(j) * nx_ + i];
  }
  bool occupiedAt(const V2& p) const {
    const int i = static_cast<int>(std::floor((p.x() - ox_) / kRes));
    const int j = static_cast<int>(std::floor((p.y() - oy_) / kRes));
    if (i < 0 || j < 0 || i >= nx_ || j >= ny_) return true;
    return occ_[static_cast<size_t>(j) * nx_ + i] != 0;
  }
  // Is the disc (p, r) free: inside one room (or through an opening), `walls_m` + the walls'
  // half thickness clear of them, and (when `furniture`) clear of furniture?
  bool discFree(const V2& p, double r, double walls_m = 0.0, bool furniture = true) const {
    const int id = idAt(p);
    if (id == 0) return false;
    const double R = r + 0.5 * kWallT + walls_m;
    for (int k = 0; k < 16; ++k) {
      const V2 u(std::cos(k * M_PI / 8), std::sin(k * M_PI / 8));
      for (double rr : {0.0, 0.5 * r, r, R}) {
        const V2 q = p + rr * u;
        const int qi = idAt(q);
        if (qi == 0) return false;
        if (qi != id && !inOpening(q, R)) return false;
        if (furniture && rr <= r + 1e-9 && occupiedAt(q)) return false;
      }
    }
    return true;
  }
  bool inOpening(const V2& p, double tol) const {
    for (const auto& o : openings)
      if (segDist(p, o.a, o.b) < tol) return true;
    return false;
  }
  // Marks a footprint (sampled polygon / disc) as furniture (+ margin).
  void occupy(const std::vector<V2>& samples) {
    for (const auto& q : samples) {
      const int i = static_cast<int>(std::floor((q.x() - ox_) / kRes));
      const int j = static_cast<int>(std::floor((q.y() - oy_) / kRes));
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
          const int a = i + di, b = j + dj;
          if (a >= 0 && b >= 0 && a < nx_ && b < ny_) occ_[static_cast<size_t>(b) * nx_ + a] = 1;
        }
    }
  }
  // Walks from p along an axis direction d (unit, axis-aligned) to the first grid boundary
  // where the room id changes: the boundary point, when that boundary is a wall (no opening).
  std::optional<V2> wallAlong(const V2& p, const V2& d, double max_m) const {
    const int id = idAt(p);
    if (id == 0) return std::nullopt;
    for (double s = kRes / 2; s < max_m; s += kRes / 2) {
      const V2 q = p + s * d;
      if (idAt(q) != id) {
        // The grid line crossed lies between the last sample in the room and q.
        const V2 mid = q - 0.25 * kRes * d;
        V2 b = p;
        if (std::abs(d.x()) > 0.5)
          b.x() = ox_ + kRes * std::round((mid.x() - ox_) / kRes);
        else
          b.y() = oy_ + kRes * std::round((mid.y() - oy_) / kRes);
        if (inOpening(b, 0.3)) return std::nullopt;
        return b;
      }
    }
    return std::nullopt;
  }

  // Walls: boundary edges between different ids, merged into straight runs that end wherever
  // another wall meets them (so walls meet only at end points: no crossing interiors).
  std::vector<std::pair<V2, V2>> walls() const {
    auto id = [&](int i, int j) {
      if (i < 0 || j < 0 || i >= nx_ || j >= ny_) return 0;
      return id_[static_cast<size_t>(j) * nx_ + i];
    };
    auto gp = [&](int i, int j) { return V2(ox_ + i * kRes, oy_ + j * kRes); };
    // v(i, j): vertical edge on grid line x_i between cells (i-1, j) and (i, j).
    auto v = [&](int i, int j) {
      if (j < 0 || j >= ny_) return false;
      if (id(i - 1, j) == id(i, j)) return false;
      return !inOpening(0.5 * (gp(i, j) + gp(i, j + 1)), 0.3 * kRes);
    };
    auto h = [&](int i, int j) {
      if (i < 0 || i >= nx_) return false;
      if (id(i, j - 1) == id(i, j)) return false;
      return !inOpening(0.5 * (gp(i, j) + gp(i + 1, j)), 0.3 * kRes);
    };
    std::vector<std::pair<V2, V2>> out;
    for (int i = 0; i <= nx_; ++i) {
      int start = -1;
      for (int j = 0; j <= ny_; ++j) {
        const bool e = j < ny_ && v(i, j);
        const bool brk = start >= 0 && (h(i - 1, j) || h(i, j));
        if (start >= 0 && (!e || brk)) {
          out.push_back({gp(i, start), gp(i, j)});
          start = -1;
        }
        if (e && start < 0) start = j;
      }
    }
    for (int j = 0; j <= ny_; ++j) {
      int start = -1;
      for (int i = 0; i <= nx_; ++i) {
        const bool e = i < nx_ && h(i, j);
        const bool brk = start >= 0 && (v(i, j - 1) || v(i, j));
        if (start >= 0 && (!e || brk)) {
          out.push_back({gp(start, j), gp(i, j)});
          start = -1;
        }
        if (e && start < 0) start = i;
      }
    }
    return out;
  }

 private:
  double ox_ = 0, oy_ = 0;
  int nx_ = 0, ny_ = 0;
  std::vector<int> id_;
  std::vector<char> occ_;
  std::vector<V2> floor_;
};

Rect around(const V2& a, const V2& b, double half) {
  return {snap(std::min(a.x(), b.x()) - half), snap(std::min(a.y(), b.y()) - half),
          snap(std::max(a.x(), b.x()) + half), snap(std::max(a.y(), b.y()) + half)};
}

V2 axisDir(int k) {
  static const V2 d[4] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
  return d[((k % 4) + 4) % 4];
}

// ---------------------------------------------------------------- families
void corridorLayout(Layout& L, Rng& rng, Json& meta) {
  const double W = 0.2 * std::round(rng.uniform(1.8, 2.6) / 0.2);  // even tenths
  const int legs = rng.chance(0.5) ? 2 : 3;
  int dir = rng.integer(0, 3);
  std::vector<V2> P{{0, 0}};
  for (int k = 0; k < legs; ++k) {
    P.push_back(P.back() + snap(rng.uniform(7, 13)) * axisDir(dir));
    dir += rng.chance(0.5) ? 1 : -1;
  }
  for (size_t k = 0; k + 1 < P.size(); ++k) L.rooms.push_back({around(P[k], P[k + 1], W / 2), 1});
  int stubs = 0;
  for (size_t k = 0; k + 1 < P.size(); ++k) {
    if (!rng.chance(0.6)) continue;
    const V2 d = (P[k + 1] - P[k]).normalized();
    const double len = (P[k + 1] - P[k]).norm();
    const V2 base = P[k] + snap(rng.uniform(2.5, len - 2.5)) * d;
    const V2 side = rot(d, rng.chance(0.5) ? M_PI / 2 : -M_PI / 2);
    L.rooms.push_back({around(base, base + snap(rng.uniform(2.5, 4.0) + W / 2) * side, W / 2), 1});
    ++stubs;
  }
  L.room_names[1] = "corridor";
  L.route = P;
  meta["corridor_width_m"] = round2(W);
  meta["t_junctions"] = stubs;
}

void hallLayout(Layout& L, Rng& rng, Json& meta) {
  const double X = snap(rng.uniform(12, 20)), Y = snap(rng.uniform(10, 15));
  L.rooms.push_back({{0, 0, X, Y}, 1});
  L.room_names[1] = "hall";
  std::vector<V2> P{{1.2, snap(rng.uniform(2, Y - 2))}};
  const int corners = rng.integer(1, 2);
  for (int k = 0; k < corners; ++k) {
    const double x0 = 2.5 + (X - 5.0) * k / corners, x1 = 2.5 + (X - 5.0) * (k + 1) / corners;
    P.push_back({snap(rng.uniform(x0 + 1, x1)), snap(rng.uniform(2, Y - 2))});
  }
  P.push_back({X - 1.5, snap(rng.uniform(2, Y - 2))});
  L.route = P;
  meta["hall_m"] = {round2(X), round2(Y)};
}

void officeLayout(Layout& L, Rng& rng, Json& meta) {
  const int n = rng.integer(2, 3);
  double x = 0;
  std::vector<double> depth;
  std::vector<V2> P;
  for (int k = 0; k < n; ++k) {
    const double w = snap(rng.uniform(5, 8)), d = snap(rng.uniform(4.5, 7));
    L.rooms.push_back({{x, 0, x + w, d}, k + 1});
    L.room_names[k + 1] = "room " + std::string(1, static_cast<char>('A' + k));
    if (k == 0) P.push_back({x + 1.0, snap(rng.uniform(1.2, d - 1.2))});
    if (k > 0) {
      const double top = std::min(depth.back(), d);
      const double dw = rng.chance(0.5) ? 1.0 : 1.2;  // even tenths: the gap is on the grid
      const double yd = snap(rng.uniform(0.8 + dw / 2, top - 0.8 - dw / 2));
      L.openings.push_back(
          {{x, yd - dw / 2}, {x, yd + dw / 2}, true, true, "door " + std::to_string(k)});
      P.push_back({x - 1.0, yd});
      P.push_back({x + 1.0, yd});
    }
    depth.push_back(d);
    x += w;
  }
  P.push_back({x - 1.2, snap(rng.uniform(1.2, depth.back() - 1.2))});
  // A closed door in an outer wall (a cupboard), off the route.
  const int k = rng.integer(0, n - 1);
  const Rect& r = L.rooms[static_cast<size_t>(k)].first;
  const double cx = snap(rng.uniform(r.x0 + 1.0, r.x1 - 1.9));
  L.openings.push_back({{cx, r.y1}, {cx + 1.0, r.y1}, true, false, "cupboard door"});
  L.route = P;
  meta["rooms"] = n;
}

void mixedLayout(Layout& L, Rng& rng, Json& meta) {
  const double X = snap(rng.uniform(7, 10)), Y = snap(rng.uniform(6, 9));
  const double W = 0.2 * std::round(rng.uniform(2.0, 2.4) / 0.2);
  const double yc = snap(rng.uniform(2.2, Y - 2.2));
  const double a = snap(rng.uniform(8, 16)), b = snap(rng.uniform(6, 12));
  const double sgn = rng.chance(0.5) ? 1 : -1;
  L.rooms.push_back({{0, 0, X, Y}, 1});
  L.room_names[1] = "lobby";
  const V2 c0(X, yc), c1(X + a, yc), c2(X + a, yc + sgn * b);
  L.rooms.push_back({around(c0 + V2(W / 2, 0), c1, W / 2), 2});
  L.rooms.push_back({around(c1, c2, W / 2), 2});
  L.room_names[2] = "corridor";
  L.openings.push_back({{X, yc - W / 2}, {X, yc + W / 2}, false, true, "archway"});
  // The room beyond the corridor's end, through a door.
  const double rw = snap(rng.uniform(5, 7)), rd = snap(rng.uniform(4.5, 6));
  const double end = snap(c2.y() + sgn * W / 2);
  const double rx0 = snap(c2.x() - rw / 2 + rng.uniform(-1, 1));
  const Rect room =
      sgn > 0 ? Rect{rx0, end, rx0 + rw, end + rd} : Rect{rx0, end - rd, rx0 + rw, end};
  L.rooms.push_back({room, 3});
  L.room_names[3] = "office";
  L.openings.push_back({{c2.x() - 0.5, end}, {c2.x() + 0.5, end}, true, true, "office door"});
  const V2 start(1.2, snap(rng.uniform(1.5, Y - 1.5)));
  const V2 goal(snap(std::clamp(c2.x() + rng.uniform(-2, 2), room.x0 + 1.2, room.x1 - 1.2)),
                snap(end + sgn * rng.uniform(2.5, rd - 1.0)));
  L.route = {start, {X - 1.5, yc}, c1, {c2.x(), end - sgn * 1.0}, {c2.x(), end + sgn * 1.2}, goal};
  meta["lobby_m"] = {round2(X), round2(Y)};
  meta["corridor_width_m"] = round2(W);
}

// ---------------------------------------------------------------- furniture and landmarks
struct Box {
  std::string name;
  V2 c;
  double sx, sy, yaw, height;
  bool cylinder = false;
  double r = 0;
  std::vector<V2> corners() const {
    const V2 ex(std::cos(yaw), std::sin(yaw)), ey(-std::sin(yaw), std::cos(yaw));
    return {c - sx / 2 * ex - sy / 2 * ey, c + sx / 2 * ex - sy / 2 * ey,
            c + sx / 2 * ex + sy / 2 * ey, c - sx / 2 * ex + sy / 2 * ey};
  }
  std::vector<V2> samples() const {
    std::vector<V2> out;
    if (cylinder) {
      for (int k = 0; k < 16; ++k)
        out.push_back(c + r * V2(std::cos(k * M_PI / 8), std::sin(k * M_PI / 8)));
      out.push_back(c);
      return out;
    }
    const auto k = corners();
    for (int e = 0; e < 4; ++e)
      for (double t = 0; t <= 1.0 + 1e-9; t += 0.1)
        out.push_back(k[e] + t * (k[(e + 1) % 4] - k[e]));
    for (double u = 0.1; u < 0.95; u += 0.2)
      for (double v = 0.1; v < 0.95; v += 0.2)
        out.push_back(k[0] + u * (k[1] - k[0]) + v * (k[3] - k[0]));
    return out;
  }
};

// The box as the world file will hold it (centimetres, hundredths of a degree): a photo on
// its face is placed from these numbers, so rounding cannot bury it in the box.
void quantise(Box& b) {
  b.c = V2(round2(b.c.x()), round2(b.c.y()));
  b.sx = round2(b.sx);
  b.sy = round2(b.sy);
  b.r = round2(b.r);
  b.yaw = round2(b.yaw / kDeg) * kDeg;
  b.height = round2(b.height);
}

struct Poster {
  std::string id, cls;
  V2 pos;
  double yaw, w, h, elevation;
  double arc = 0;  // along the route, where it is passed
  std::string on;  // "wall", "furniture face", "furniture top"
};

struct World {
  Layout L;
  std::vector<Box> boxes;
  std::vector<Poster> posters;
  Json pedestrians = Json::array();
};

// A footprint fits: inside one room (clear of its walls), clear of furniture, and at least
// `route_m` from the route.
bool fits(const World& W, const Box& b, double route_m) {
  const auto s = b.samples();
  const int id = W.L.idAt(b.c);
  if (id == 0) return false;
  for (const auto& q : s) {
    if (W.L.idAt(q) != id || W.L.occupiedAt(q)) return false;
    if (polyDist(q, W.L.route) < route_m) return false;
  }
  // Clear of the walls' half thickness (5 cm into the room, 3 cm tolerated): probe 4 cm out.
  for (const auto& q : s)
    for (const V2& d : {V2(0.04, 0), V2(-0.04, 0), V2(0, 0.04), V2(0, -0.04)})
      if (W.L.idAt(q + d) != id) return false;
  return true;
}

void addBox(World& W, Box b) {
  W.L.occupy(b.samples());
  W.boxes.push_back(std::move(b));
}

// A box standing with its back against the wall at `wall_pt` (a boundary point, wall normal
// `n` pointing into the room).
Box againstWall(const std::string& name, const V2& wall_pt, const V2& n, double width, double depth,
                double height) {
  Box b;
  b.name = name;
  b.c = wall_pt + n * (0.5 * kWallT + depth / 2 + 0.005);
  b.yaw = std::atan2(n.y(), n.x());  // box x along the normal
  b.sx = depth;
  b.sy = width;
  b.height = height;
  return b;
}

// The wall continues for `half` either side of the point along it (the poster / box fits).
bool wallContinues(const Layout& L, const V2& from, const V2& d, double dist, double half) {
  const V2 t(-d.y(), d.x());
  for (double s : {-half, half, -half / 2, half / 2}) {
    const auto w = L.wallAlong(from + s * t, d, dist + 0.5);
    if (!w || std::abs((*w - (from + s * t)).dot(d) - dist) > 0.06) return false;
  }
  return true;
}

V2 nearestAxis(const V2& v) {
  return std::abs(v.x()) >= std::abs(v.y()) ? V2(v.x() > 0 ? 1 : -1, 0) : V2(0, v.y() > 0 ? 1 : -1);
}

// Tries to hang a landmark for route arc `s`: on the wall to one side, on a cabinet against
// that wall (face or top), or on a piece of furniture standing in the room facing the route.
std::optional<Poster> placeLandmark(World& W, Rng& rng, double s, bool open_room, int n) {
  const auto [p, dir] = along(W.L.route, s);
  std::vector<int> kinds = {0, 0, 1, 2};
  if (open_room) kinds.push_back(3);
  for (int attempt = 0; attempt < 6; ++attempt) {
    const int kind = rng.pick(kinds);
    const V2 side = nearestAxis(rot(dir, rng.chance(0.5) ? M_PI / 2 : -M_PI / 2));
    Poster ps;
    ps.id = "L" + std::to_string(n);
    ps.w = round2(rng.uniform(0.35, 0.6));
    ps.h = round2(ps.w * rng.uniform(0.8, 1.25));
    ps.arc = s;
    if (kind == 3) {
      // A cabinet / display standing in the room, turned to face the route roughly.
      Box b;
      b.name = "display " + std::to_string(n);
      const double off = rng.uniform(1.6, 3.5);
      b.c =
          p + off * rot(dir, rng.chance(0.5) ? M_PI / 2 : -M_PI / 2) + rng.uniform(-0.5, 0.5) * dir;
      const V2 to_route = (p - b.c).normalized();
      const double face_yaw = std::atan2(to_route.y(), to_route.x()) + rng.uniform(-40, 40) * kDeg;
      b.sx = rng.uniform(0.4, 0.6);
      b.sy = rng.uniform(0.8, 1.4);
      b.yaw = face_yaw;
      b.height = rng.uniform(1.0, 1.6);
      quantise(b);
      if (!fits(W, b, 1.0)) continue;
      ps.yaw = b.yaw;
      ps.pos = b.c + (b.sx / 2 + 0.001) * V2(std::cos(b.yaw), std::sin(b.yaw));
      ps.elevation = round2(std::min(b.height - ps.h / 2 - 0.05, rng.uniform(0.6, 1.2)));
      if (ps.elevation - ps.h / 2 < 0.05) continue;
      ps.on = "furniture face";
      addBox(W, b);
      return ps;
    }
    const auto wall = W.L.wallAlong(p, side, 6.0);
    if (!wall) continue;
    const double dist = (*wall - p).dot(side);
    const V2 n_in = -side;
    if (kind <= 1) {
      if (kind == 0) {
        if (dist < 0.8 || !wallContinues(W.L, p, side, dist, ps.w / 2 + 0.1)) continue;
        ps.pos = *wall + n_in * (0.5 * kWallT);
        // Keep clear of furniture already against that wall.
        if (W.L.occupiedAt(ps.pos + n_in * 0.08)) continue;
        ps.yaw = std::atan2(n_in.y(), n_in.x());
        ps.elevation = round2(rng.uniform(std::max(0.5, ps.h / 2 + 0.1), 1.4));
        ps.on = "wall";
        return ps;
      }
      // kind 1: a cabinet against the wall, the photo on its front face or on its top.
      const double depth = rng.uniform(0.4, 0.6), width = rng.uniform(0.8, 1.4);
      if (dist - kWallT / 2 - depth < 0.95) continue;  // the robot must still pass it
      if (!wallContinues(W.L, p, side, dist, width / 2 + 0.05)) continue;
      const bool top = rng.chance(0.4);
      Box b = againstWall((top ? "low cabinet " : "cabinet ") + std::to_string(n), *wall, n_in,
                          width, depth, top ? rng.uniform(0.7, 1.0) : rng.uniform(1.2, 1.9));
      quantise(b);
      if (!fits(W, b, 0.7)) continue;
      ps.yaw = std::atan2(n_in.y(), n_in.x());
      if (top) {
        ps.pos = b.c;
        ps.elevation = round2(b.height + ps.h / 2 + 0.01);
        ps.on = "furniture top";
      } else {
        ps.pos = b.c + n_in * (b.sx / 2 + 0.001);
        ps.elevation =
            round2(std::clamp(rng.uniform(0.5, 1.2), ps.h / 2 + 0.1, b.height - ps.h / 2 - 0.05));
        ps.on = "furniture face";
      }
      addBox(W, b);
      return ps;
    }
    // kind 2: the wall ahead at the end of the current leg (facing the robot).
    {
      const V2 ahead = nearestAxis(dir);
      const auto w2 = W.L.wallAlong(p, ahead, 7.0);
      if (!w2) continue;
      const double d2 = (*w2 - p).dot(ahead);
      if (d2 < 2.0 || !wallContinues(W.L, p, ahead, d2, ps.w / 2 + 0.1)) continue;
      ps.pos = *w2 - ahead * (0.5 * kWallT) + rot(ahead, M_PI / 2) * rng.uniform(-0.3, 0.3);
      if (!wallContinues(W.L, ps.pos - ahead * 0.5, ahead, 0.5 + 0.5 * kWallT - 0.0,
                         ps.w / 2 + 0.1))
        continue;
      if (W.L.occupiedAt(ps.pos - ahead * 0.08)) continue;
      ps.yaw = std::atan2(-ahead.y(), -ahead.x());
      ps.elevation = round2(rng.uniform(std::max(0.5, ps.h / 2 + 0.1), 1.4));
      ps.on = "wall";
      return ps;
    }
  }
  return std::nullopt;
}

// Furniture off the route (desks, cabinets, bins, pillars): the clutter of a real place.
void addClutter(World& W, Rng& rng, const std::string& family) {
  const int n = family == "corridor" ? rng.integer(1, 3) : rng.integer(3, 7);
  const double len = polyLength(W.L.route);
  for (int k = 0, tries = 0; k < n && tries < 60; ++tries) {
    const auto [p, dir] = along(W.L.route, rng.uniform(0.5, len));
    const V2 side = nearestAxis(rot(dir, rng.chance(0.5) ? M_PI / 2 : -M_PI / 2));
    Box b;
    const int kind = rng.integer(0, family == "corridor" ? 1 : 3);
    if (kind == 0) {  // a bin / plant by the wall
      const auto wall = W.L.wallAlong(p, side, 4.0);
      if (!wall) continue;
      b.cylinder = true;
      b.r = round2(rng.uniform(0.15, 0.3));
      b.c = *wall - side * (0.5 * kWallT + b.r + 0.01);
      b.height = round2(rng.uniform(0.5, 1.2));
      b.name = "bin " + std::to_string(k + 1);
      b.sx = b.sy = 2 * b.r;
      b.yaw = 0;
      if (!fits(W, b, 0.75)) continue;
    } else if (kind == 1) {  // a desk / shelf against the wall
      const auto wall = W.L.wallAlong(p, side, 5.0);
      if (!wall) continue;
      const double depth = rng.uniform(0.4, 0.8), width = rng.uniform(0.8, 1.8);
      if (!wallContinues(W.L, p, side, (*wall - p).dot(side), width / 2 + 0.05)) continue;
      b = againstWall((rng.chance(0.5) ? "desk " : "shelf ") + std::to_string(k + 1), *wall, -side,
                      width, depth, rng.uniform(0.7, 2.0));
      if (!fits(W, b, 0.85)) continue;
    } else if (kind == 2) {  // a table in the room
      b.name = "table " + std::to_string(k + 1);
      b.c = p + rng.uniform(1.6, 5) * side + rng.uniform(-1, 1) * dir;
      b.sx = rng.uniform(0.8, 2.0);
      b.sy = rng.uniform(0.6, 1.0);
      b.yaw = rng.chance(0.5) ? 0.0 : rng.uniform(-M_PI / 2, M_PI / 2);
      b.height = rng.uniform(0.7, 0.8);
      if (!fits(W, b, 1.0)) continue;
    } else {  // a pillar
      b.cylinder = true;
      b.r = round2(rng.uniform(0.15, 0.3));
      b.c = p + rng.uniform(1.5, 5) * side + rng.uniform(-1, 1) * dir;
      b.height = 2.5;
      b.name = "pillar " + std::to_string(k + 1);
      b.sx = b.sy = 2 * b.r;
      b.yaw = 0;
      if (!fits(W, b, 1.0)) continue;
    }
    quantise(b);
    addBox(W, b);
    ++k;
  }
}

// People on straight stretches of the route: some walk along it and keep going (the robot
// must get round them), some walk along it and step to the side before they would meet the
// robot. The simulator's pedestrians follow their polyline back and forth whatever the robot
// does; "stepping aside" is in the path.
void addPeople(World& W, Rng& rng, Json& meta) {
  const int n = rng.chance(0.55) ? (rng.chance(0.35) ? 2 : 1) : 0;
  Json kinds = Json::array();
  for (int k = 0, tries = 0; k < n && tries < 40; ++tries) {
    // A leg at least 6 m long, the walk starting at least 4 m from the start.
    const auto& R = W.L.route;
    double s = 0;
    std::vector<std::pair<double, double>> legs;
    for (size_t i = 0; i + 1 < R.size(); ++i) {
      const double L = (R[i + 1] - R[i]).norm();
      const double a = std::max(s + 0.5, 4.0), b = s + L - 0.5;
      if (b - a >= 5.0) legs.push_back({a, b});
      s += L;
    }
    if (legs.empty()) break;
    const auto [a, b] = rng.pick(legs);
    const double s1 = rng.uniform(a, b - 4.5), s2 = rng.uniform(s1 + 4.0, b);
    const auto [p1, d] = along(R, s1);
    const auto [p2, d2] = along(R, s2);
    (void)d2;
    const V2 lat = rot(d, M_PI / 2);
    const bool aside = rng.chance(0.5);
    const double radius = 0.25;
    std::vector<V2> path;
    if (aside) {
      const double sm = rng.uniform(s1 + 1.5, s2 - 1.5);
      const double off = (rng.chance(0.5) ? 1 : -1) * rng.uniform(0.7, 0.95);
      path = {p2, along(R, sm).first, along(R, sm - 1.0).first + off * lat, p1 + off * lat};
    } else {
      const double off = rng.uniform(-0.3, 0.3);
      path = {p2 + off * lat, p1 + off * lat};
    }
    bool ok = true;
    for (size_t i = 0; ok && i + 1 < path.size(); ++i)
      for (double t = 0; ok && t <= 1.0; t += 0.05)
        ok = W.L.discFree(path[i] + t * (path[i + 1] - path[i]), radius + 0.05);
    if (!ok) continue;
    Json jp = Json::array();
    for (const auto& q : path) jp.push_back(j2(q));
    const double speed = round2(rng.uniform(0.3, 0.6));
    W.pedestrians.push_back(
        {{"name",
          std::string(aside ? "person stepping aside " : "person ") + std::to_string(k + 1)},
         {"path", jp},
         {"speed", speed},
         {"phase", round2(rng.uniform(0, polyLength(path)))},
         {"radius", radius},
         {"color", {rng.integer(40, 200), rng.integer(40, 200), rng.integer(40, 200)}}});
    kinds.push_back({{"kind", aside ? "steps_aside" : "keeps_walking"}, {"speed", speed}});
    ++k;
  }
  meta["people"] = kinds;
}

// An unsketched box partly in the way (the robot has to get round it; a way is checked).
void addObstacleInTheWay(World& W, Rng& rng, Json& meta) {
  meta["obstacle_in_the_way"] = false;
  if (!rng.chance(0.3)) return;
  const double len = polyLength(W.L.route);
  for (int tries = 0; tries < 20; ++tries) {
    const double s = rng.uniform(3.0, len - 3.0);
    const auto [p, d] = along(W.L.route, s);
    Box b;
    b.name = "box in the way";
    b.sx = rng.uniform(0.4, 0.7);
    b.sy = rng.uniform(0.4, 0.7);
    b.yaw = std::atan2(d.y(), d.x());
    b.c = p + rng.uniform(-0.3, 0.3) * rot(d, M_PI / 2);
    b.height = round2(rng.uniform(0.5, 1.0));
    quantise(b);
    // Inside its room with the robot's way round it on at least one side.
    bool ok = true;
    for (const auto& q : b.samples()) ok = ok && W.L.idAt(q) == W.L.idAt(b.c) && !W.L.occupiedAt(q);
    if (!ok || W.L.inOpening(b.c, 2.0)) continue;
    // Away from the landmarks' faces and the start and goal.
    if ((b.c - W.L.route.front()).norm() < 2.5 || (b.c - W.L.route.back()).norm() < 2.0) continue;
    if (!W.L.discFree(b.c, std::max(b.sx, b.sy) / 2 + 0.1, 0.0, true)) continue;
    addBox(W, b);
    meta["obstacle_in_the_way"] = true;
    meta["obstacle_arc_m"] = round2(s);
    return;
  }
}

// The robot: the lab's (camera pitched up 12 deg; laser, sonar and body as the defaults).
Json robotJson() {
  Json j = Json::object();
  j["camera"] = Json::object({{"width", 640},
                              {"height", 480},
                              {"hfov_deg", 60},
                              {"x", 0.1},
                              {"y", 0.0},
                              {"z", 0.3},
                              {"yaw_deg", 0},
                              {"pitch_deg", 12},
                              {"near", 0.05},
                              {"far", 30}});
  j["robot"] = Json::object({{"radius", 0.2}});
  return j;
}

std::string textureOf(const std::string& cls) {
  return "textures/" + cls + "/" + cls + "_Iconic.jpg";
}

Json worldJson(const World& W, const std::string& name, const std::string& family, double start_yaw,
               Rng& rng) {
  Json j;
  j["name"] = name;
  j["description"] = "generated by sketchnav scenarios (" + family + ")";
  Json fl = Json::array();
  for (const auto& q : W.L.floor()) fl.push_back(j2(q));
  j["floor"] = fl;
  Json walls = Json::array();
  int k = 0;
  for (const auto& [a, b] : W.L.walls())
    walls.push_back({{"name", "wall " + std::to_string(++k)},
                     {"from", j2(a)},
                     {"to", j2(b)},
                     {"thickness", kWallT},
                     {"height", 2.5}});
  j["walls"] = walls;
  Json doors = Json::array();
  for (const auto& o : W.L.openings)
    if (o.door)
      doors.push_back({{"name", o.name}, {"from", j2(o.a)}, {"to", j2(o.b)}, {"open", o.open}});
  j["doors"] = doors;
  Json obs = Json::array();
  for (const auto& b : W.boxes) {
    Json o = {{"name", b.name},
              {"centre", j2(b.c)},
              {"height", b.height},
              {"color", {rng.integer(70, 200), rng.integer(70, 200), rng.integer(70, 200)}}};
    if (b.cylinder) {
      o["shape"] = "cylinder";
      o["radius"] = b.r;
    } else {
      o["shape"] = "box";
      o["size"] = {round2(b.sx), round2(b.sy)};
      o["yaw_deg"] = round2(b.yaw / kDeg);
    }
    obs.push_back(o);
  }
  j["obstacles"] = obs;
  Json lms = Json::array();
  for (const auto& p : W.posters)
    lms.push_back(
        {{"id", p.id},
         {"class", p.cls},
         {"texture", textureOf(p.cls)},
         {"position", {std::round(p.pos.x() * 1000) / 1000, std::round(p.pos.y() * 1000) / 1000}},
         {"yaw_deg", round2(p.yaw / kDeg)},
         {"width", p.w},
         {"height", p.h},
         {"elevation", p.elevation}});
  j["landmarks"] = lms;
  j["pedestrians"] = W.pedestrians;
  j["start"] = {{"x", round2(W.L.route.front().x())},
                {"y", round2(W.L.route.front().y())},
                {"yaw_deg", round2(start_yaw / kDeg)}};
  j["goal"] = {
      {"x", round2(W.L.route.back().x())}, {"y", round2(W.L.route.back().y())}, {"radius", 0.5}};
  j["lighting"] = {{"brightness", round2(rng.uniform(0.85, 1.15))},
                   {"variation", round2(rng.uniform(0.0, 0.1))},
                   {"period", 45.0}};
  const Json robot = robotJson();
  for (const auto& [key, v] : robot.items()) j[key] = v;
  return j;
}

// ---------------------------------------------------------------- the sketch
struct Drawn {
  Json sketch;
  std::vector<SketchErrorRecord> errors;
};

Drawn drawSketch(const World& W, const std::vector<Poster>& remembered, const std::string& name,
                 Rng& rng, const SketchErrorBounds& B, const std::set<std::string>& kinds) {
  Drawn out;
  std::vector<V2> R = W.L.route;
  // Corners misplaced (not the start or goal: the user knows those).
  if (kinds.count("corners_misplaced") && R.size() > 2) {
    double mx = 0;
    for (size_t i = 1; i + 1 < R.size(); ++i) {
      const V2 e(rng.clippedNormal(B.corner_m / 2, B.corner_m / std::sqrt(2.0)),
                 rng.clippedNormal(B.corner_m / 2, B.corner_m / std::sqrt(2.0)));
      R[i] += e;
      mx = std::max(mx, e.norm());
    }
    out.errors.push_back({"corners_misplaced", {{"max_m", round2(mx)}, {"corners", R.size() - 2}}});
  }
  // One corner drawn on the wrong side of the line joining its neighbours, where that is
  // still inside the room (an open hall / lobby: "we went round the other way").
  if (kinds.count("corner_wrong_side") && R.size() > 2) {
    for (size_t i = 1; i + 1 < R.size(); ++i) {
      const V2 a = R[i - 1], b = R[i + 1], d = (b - a).normalized();
      const V2 q = a + d * (R[i] - a).dot(d);
      const V2 m = 2 * q - R[i];
      if ((m - R[i]).norm() < 1.0) continue;
      bool inside = true;
      for (double t = 0; t <= 1.0 && inside; t += 0.05)
        inside = W.L.discFree(a + t * (m - a), 0.3, 0.0, false) &&
                 W.L.discFree(m + t * (b - m), 0.3, 0.0, false);
      if (!inside) continue;
      out.errors.push_back(
          {"corner_wrong_side",
           {{"corner", i}, {"moved_m", round2((m - R[i]).norm())}, {"drawn_at", j2(m)}}});
      R[i] = m;
      break;
    }
  }
  // The drawing transform: rotation and anisotropic scale of the whole drawing.
  double theta = 0, sx = 1, sy = 1;
  if (kinds.count("rotation")) {
    theta = signedMagnitude(rng, 5, B.rotation_deg) * kDeg;
    out.errors.push_back({"rotation", {{"deg", round2(theta / kDeg)}}});
  }
  if (kinds.count("anisotropic_scale")) {
    sx = 1 + signedMagnitude(rng, 0.04, B.scale);
    sy = 1 + rng.uniform(-B.scale, B.scale);
    if (rng.chance(0.5)) std::swap(sx, sy);
    out.errors.push_back(
        {"anisotropic_scale",
         {{"x", std::round(sx * 1000) / 1000}, {"y", std::round(sy * 1000) / 1000}}});
  }
  auto D = [&](const V2& p) {
    const V2 r = rot(p, theta);
    return V2(sx * r.x(), sy * r.y());
  };
  // Landmark boxes where the person remembers them.
  std::vector<V2> lm_drawn;
  for (const auto& p : remembered) {
    const V2 e(rng.clippedNormal(B.landmark_sigma_m, 2 * B.landmark_sigma_m),
               rng.clippedNormal(B.landmark_sigma_m, 2 * B.landmark_sigma_m));
    // The box is drawn in the room, a little towards the route from the wall it hangs on.
    lm_drawn.push_back(D(p.pos + e));
  }
  std::vector<V2> Rd;
  for (const auto& q : R) Rd.push_back(D(q));
  // Fit to a 1000 x 720 canvas, 70 px margin, y down.
  double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
  auto grow = [&](const V2& q) {
    x0 = std::min(x0, q.x()), y0 = std::min(y0, q.y()), x1 = std::max(x1, q.x()),
    y1 = std::max(y1, q.y());
  };
  for (const auto& q : Rd) grow(q);
  for (const auto& q : lm_drawn) grow(q);
  const double k =
      std::min((1000 - 140) / std::max(x1 - x0, 1.0), (720 - 140) / std::max(y1 - y0, 1.0));
  auto C = [&](const V2& q) { return V2(70 + k * (q.x() - x0), 720 - 70 - k * (q.y() - y0)); };
  Json path = Json::array();
  for (size_t i = 0; i + 1 < Rd.size(); ++i) {
    const V2 a = C(Rd[i]), b = C(Rd[i + 1]);
    const int n = std::max(1, static_cast<int>((b - a).norm() / 5.0));
    for (int s = 0; s < n; ++s) {
      const V2 q = a + (b - a) * (static_cast<double>(s) / n) +
                   V2(rng.clippedNormal(B.jitter_px, 3 * B.jitter_px),
                      rng.clippedNormal(B.jitter_px, 3 * B.jitter_px));
      path.push_back({std::round(q.x() * 10) / 10, std::round(q.y() * 10) / 10});
    }
  }
  const V2 goal_px = C(Rd.back()), start_px = C(Rd.front());
  path.push_back({std::round(goal_px.x() * 10) / 10, std::round(goal_px.y() * 10) / 10});
  // Distances in route order, from the previous landmark (the start for the first): the true
  // distance between the remembered places, biased and noisy, rounded as people say them.
  double bias = 1;
  if (kinds.count("distance_bias")) {
    bias = 1 + signedMagnitude(rng, 0.1, B.distance_bias);
    out.errors.push_back({"distance_bias", {{"factor", std::round(bias * 1000) / 1000}}});
  }
  std::vector<size_t> order(remembered.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return mapsketch::closestOnPolyline(remembered[a].pos, W.L.route).arc <
           mapsketch::closestOnPolyline(remembered[b].pos, W.L.route).arc;
  });
  Json lms = Json::array();
  V2 prev = W.L.route.front();
  for (size_t oi : order) {
    const auto& p = remembered[oi];
    double d = (p.pos - prev).norm() * bias *
               (1 + rng.clippedNormal(B.distance_noise, 2 * B.distance_noise));
    d = std::max(B.distance_round_m, std::round(d / B.distance_round_m) * B.distance_round_m);
    prev = p.pos;
    const V2 c = C(lm_drawn[oi]);
    const double w = 56, h = 38;
    lms.push_back(
        {{"id", p.id},
         {"class", p.cls},
         {"rect",
          {{"x", std::round(c.x() - w / 2)}, {"y", std::round(c.y() - h / 2)}, {"w", w}, {"h", h}}},
         {"distance_m", d}});
  }
  out.sketch = {{"format", 1},
                {"name", name + " (generated sketch)"},
                {"notes", "Generated by sketchnav scenarios with recorded drawing errors (" + name +
                              ".scenario.json)."},
                {"canvas", {{"width", 1000}, {"height", 720}}},
                {"landmarks", lms},
                {"path", path},
                {"start", {std::round(start_px.x() * 10) / 10, std::round(start_px.y() * 10) / 10}},
                {"goal", {std::round(goal_px.x() * 10) / 10, std::round(goal_px.y() * 10) / 10}}};
  return out;
}

// The checks' warnings: the world's geometry and the start heading against the sketch.
std::vector<std::string> scenarioWarnings(const GeneratedScenario& g) {
  std::vector<std::string> out;
  try {
    const sim::World w = sim::worldFromJson(g.world, g.name, resourceDir());
    for (const auto& i : sim::checkWorldGeometry(w)) out.push_back(i.text(g.name));
    const auto route = mapsketch::toRoute(mapsketch::sketchFromJson(g.sketch, g.name));
    sim::RoutePlacement placed{route.start_m, route.start_heading_rad, {}};
    for (const auto& sec : route.sections)
      for (const auto& lm : sec.landmarks) placed.landmarks.push_back({lm.id, lm.position_m});
    for (const auto& i : sim::checkStartHeading(w, placed, g.name + ".sketch.json"))
      out.push_back(i.text(g.name));
  } catch (const InputError& e) {
    out.push_back(e.what());
  }
  return out;
}

std::optional<GeneratedScenario> attempt(const std::string& family, std::uint64_t seed, int att,
                                         const std::vector<std::string>& classes,
                                         const SketchErrorBounds& B) {
  Rng rng(seed * 0x9E3779B97F4A7C15ull + static_cast<std::uint64_t>(att) * 0xD1B54A32D192ED03ull +
          0x5CE7A5ull);
  GeneratedScenario g;
  g.family = family;
  g.seed = seed;
  g.name = family + "-" + std::to_string(seed);
  g.attempts = att + 1;
  World W;
  Json meta;
  if (family == "corridor")
    corridorLayout(W.L, rng, meta);
  else if (family == "hall")
    hallLayout(W.L, rng, meta);
  else if (family == "office")
    officeLayout(W.L, rng, meta);
  else
    mixedLayout(W.L, rng, meta);
  W.L.rasterise();
  const double len = polyLength(W.L.route);
  // Landmarks along the route every 3.5-6 m.
  std::vector<std::string> pool = classes;
  int n = 0;
  const bool open_room = family == "hall" || family == "mixed";
  for (double s = rng.uniform(1.8, 3.0); s < len - 1.0; s += rng.uniform(3.5, 6.0)) {
    if (auto p = placeLandmark(W, rng, s, open_room, n + 1)) {
      if (pool.empty()) pool = classes;
      const size_t ci = static_cast<size_t>(rng.integer(0, static_cast<int>(pool.size()) - 1));
      p->cls = pool[ci];
      pool.erase(pool.begin() + static_cast<long>(ci));
      std::vector<V2> strip;
      const V2 t(-std::sin(p->yaw), std::cos(p->yaw)), nn(std::cos(p->yaw), std::sin(p->yaw));
      for (double u = -p->w / 2; u <= p->w / 2 + 1e-9; u += 0.05)
        strip.push_back(p->pos + u * t + 0.05 * nn);
      W.L.occupy(strip);
      W.posters.push_back(*p);
      ++n;
    }
  }
  if (W.posters.size() < 3) {
    if (std::getenv("SKETCHNAV_SCENARIO_DEBUG"))
      std::fprintf(stderr, "%s attempt %d: %zu landmarks placed\n", g.name.c_str(), att,
                   W.posters.size());
    return std::nullopt;
  }
  // Now and then two landmarks of the same class (disambiguated by order and place).
  meta["repeated_class"] = false;
  if (W.posters.size() >= 4 && rng.chance(0.25)) {
    const size_t a = static_cast<size_t>(rng.integer(0, static_cast<int>(W.posters.size()) - 3));
    W.posters[a + 2].cls = W.posters[a].cls;
    meta["repeated_class"] = W.posters[a].cls;
  }
  addClutter(W, rng, family);
  addObstacleInTheWay(W, rng, meta);
  addPeople(W, rng, meta);

  // Which drawing errors this scenario gets.
  std::set<std::string> kinds;
  for (const auto& k : kKinds)
    if (rng.chance(B.p_kind)) kinds.insert(k);
  // What the person remembers: the landmarks as they were; then the world changes (a poster
  // taken down, one moved along its wall) without the sketch knowing.
  std::vector<Poster> remembered = W.posters;
  if (kinds.count("landmark_missing") && W.posters.size() >= 4) {
    const size_t i = static_cast<size_t>(rng.integer(1, static_cast<int>(W.posters.size()) - 1));
    g.errors.push_back({"landmark_missing", {{"id", W.posters[i].id}}});
    W.posters.erase(W.posters.begin() + static_cast<long>(i));
  }
  if (kinds.count("landmark_moved")) {
    for (int tries = 0; tries < 10; ++tries) {
      const size_t i = static_cast<size_t>(rng.integer(0, static_cast<int>(W.posters.size()) - 1));
      Poster& p = W.posters[i];
      if (p.on != "wall") continue;
      const V2 t(-std::sin(p.yaw), std::cos(p.yaw));  // along the wall
      const double m = (rng.chance(0.5) ? 1 : -1) * rng.uniform(B.move_min_m, B.move_max_m);
      const V2 q = p.pos + m * t;
      const V2 n_in(std::cos(p.yaw), std::sin(p.yaw));
      const V2 probe = q + n_in * 0.5;
      if (!W.L.discFree(probe, 0.05, 0.0, false) || W.L.occupiedAt(q + n_in * 0.08)) continue;
      const auto w = W.L.wallAlong(probe, -n_in, 0.8);
      if (!w || std::abs((*w - probe).dot(-n_in) - (0.5 + 0.5 * kWallT)) > 0.06 ||
          !wallContinues(W.L, probe, -n_in, 0.5 + 0.5 * kWallT, p.w / 2 + 0.1))
        continue;
      p.pos = q;
      g.errors.push_back({"landmark_moved", {{"id", p.id}, {"moved_m", round2(std::abs(m))}}});
      break;
    }
  }
  const V2 d0 = W.L.route[1] - W.L.route[0];
  double start_yaw = std::atan2(d0.y(), d0.x());
  if (kinds.count("start_heading")) {
    const double e = signedMagnitude(rng, 5, B.heading_deg);
    start_yaw += e * kDeg;
    g.errors.push_back({"start_heading", {{"deg", round2(e)}}});
  }
  g.world = worldJson(W, g.name, family, start_yaw, rng);
  Drawn dr = drawSketch(W, remembered, g.name, rng, B, kinds);
  g.sketch = dr.sketch;
  for (auto& e : dr.errors) {
    // The first corner drawn round the other way: the person puts the robot down facing the
    // way they drew (the start heading error, if any, on top).
    if (e.kind == "corner_wrong_side" && e.params["corner"] == 1) {
      const V2 m(e.params["drawn_at"][0].get<double>(), e.params["drawn_at"][1].get<double>());
      const V2 d = m - W.L.route[0];
      const double yaw = std::atan2(d.y(), d.x()) + (start_yaw - std::atan2(d0.y(), d0.x()));
      g.world["start"]["yaw_deg"] = round2(yaw / kDeg);
    }
    g.errors.push_back(e);
  }
  // Report order.
  std::stable_sort(g.errors.begin(), g.errors.end(), [](const auto& a, const auto& b) {
    return std::find(kKinds.begin(), kKinds.end(), a.kind) <
           std::find(kKinds.begin(), kKinds.end(), b.kind);
  });
  g.route = W.L.route;
  meta["route_length_m"] = round2(len);
  meta["landmarks_world"] = W.posters.size();
  meta["landmarks_sketched"] = remembered.size();
  Json placed = Json::array();
  for (const auto& p : W.posters) placed.push_back({{"id", p.id}, {"on", p.on}});
  meta["landmark_places"] = placed;
  g.meta = meta;
  if (const auto problems = scenarioProblems(g, classes); !problems.empty()) {
    if (std::getenv("SKETCHNAV_SCENARIO_DEBUG"))
      std::fprintf(stderr, "%s attempt %d: %s\n", g.name.c_str(), att, problems.front().c_str());
    return std::nullopt;
  }
  // No warnings either: a generated world is meant to be clean (a free-standing board or
  // overlapping furniture would be the generator's slip, not a test of the robot).
  g.warnings = scenarioWarnings(g);
  if (!g.warnings.empty()) {
    if (std::getenv("SKETCHNAV_SCENARIO_DEBUG"))
      std::fprintf(stderr, "%s attempt %d: %s\n", g.name.c_str(), att, g.warnings.front().c_str());
    return std::nullopt;
  }
  return g;
}

}  // namespace

const std::vector<std::string>& sketchErrorKinds() {
  return kKinds;
}
const std::vector<std::string>& scenarioFamilies() {
  return kFamilies;
}

bool GeneratedScenario::hasError(const std::string& kind) const {
  for (const auto& e : errors)
    if (e.kind == kind) return true;
  return false;
}

Json GeneratedScenario::toJson() const {
  Json errs = Json::array();
  for (const auto& e : errors) errs.push_back({{"kind", e.kind}, {"params", e.params}});
  Json r = Json::array();
  for (const auto& q : route) r.push_back(j2(q));
  return {{"name", name},   {"family", family}, {"seed", seed}, {"attempts", attempts},
          {"errors", errs}, {"route", r},       {"meta", meta}, {"warnings", warnings}};
}

std::vector<std::string> scenarioProblems(const GeneratedScenario& s,
                                          const std::vector<std::string>& classes) {
  std::vector<std::string> out;
  sim::World w;
  try {
    w = sim::worldFromJson(s.world, s.name + ".world.json", resourceDir());
  } catch (const InputError& e) {
    return {e.what()};
  }
  for (const auto& i : sim::checkLandmarkClasses(w, classes)) out.push_back(i.text(s.name));
  mapsketch::Route route;
  try {
    const auto sk = mapsketch::sketchFromJson(s.sketch, s.name + ".sketch.json");
    mapsketch::validateClasses(sk, classes, s.name + ".sketch.json");
    route = mapsketch::toRoute(sk);
  } catch (const InputError& e) {
    out.push_back(e.what());
    return out;
  }
  sim::RoutePlacement placed{route.start_m, route.start_heading_rad, {}};
  for (const auto& sec : route.sections)
    for (const auto& lm : sec.landmarks) placed.landmarks.push_back({lm.id, lm.position_m});
  for (const auto& i : sim::checkStartHeading(w, placed, s.name + ".sketch.json"))
    if (i.isError()) out.push_back(i.text(s.name));
  if (sim::freePathLength(w) < 0)
    out.push_back(s.name + ": no free path from the start to the goal");
  return out;
}

GeneratedScenario generateScenario(const std::string& family, std::uint64_t seed,
                                   const std::vector<std::string>& classes,
                                   const SketchErrorBounds& bounds) {
  if (std::find(kFamilies.begin(), kFamilies.end(), family) == kFamilies.end())
    throw InputError("unknown scenario family '" + family +
                     "' (known: corridor, hall, office, mixed)");
  if (classes.size() < 2) throw InputError("the landmark set needs at least two classes");
  for (int att = 0; att < 30; ++att)
    if (auto g = attempt(family, seed, att, classes, bounds)) return *g;
  throw RuntimeError("scenario " + family + "-" + std::to_string(seed) +
                     ": no layout passed the checks in 30 attempts");
}

std::string writeScenario(const GeneratedScenario& s, const std::string& dir) {
  std::filesystem::create_directories(dir);
  const std::string base = dir + "/" + s.name;
  std::ofstream(base + ".world.json") << s.world.dump(1) << "\n";
  std::ofstream(base + ".sketch.json") << s.sketch.dump(1) << "\n";
  std::ofstream(base + ".scenario.json") << s.toJson().dump(1) << "\n";
  return base + ".world.json";
}

}  // namespace sketchnav::run
