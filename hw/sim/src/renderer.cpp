#include "renderer.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

#include "sketchnav/core/error.h"
#include "sketchnav/core/image_file.h"

namespace sketchnav::sim {
namespace {

using Eigen::Vector3d;

const Vector3d kLight = Vector3d(0.45, 0.7, 0.55).normalized();

float lambert(const Vector3d& n) {
  // Ambient + diffuse, with |n.L| so both sides of a plane get some light: rooms are lit from
  // many directions; what matters is that differently oriented faces differ.
  return static_cast<float>(0.62 + 0.38 * std::abs(n.dot(kLight)));
}

void finishFace(Face& f) {
  f.centre.setZero();
  for (const auto& p : f.poly) f.centre += p;
  f.centre /= static_cast<double>(f.poly.size());
  f.radius = 0;
  for (const auto& p : f.poly) f.radius = std::max(f.radius, (p - f.centre).norm());
  f.shade = lambert(f.normal);
}

/// A vertical rectangle of width w, height h (bottom at z0) whose visible side faces `n2`
/// (unit, horizontal); `left` is its bottom-left corner as seen by a viewer facing it.
Face verticalRect(const Vec2& left, const Vec2& n2, double w, double z0, double h, Face::Kind kind,
                  const cv::Scalar& color) {
  Face f;
  f.kind = kind;
  f.normal = Vector3d(n2.x(), n2.y(), 0);
  f.es = Vector3d(-n2.y(), n2.x(), 0);  // the viewer's right
  f.et = Vector3d::UnitZ();
  f.origin = Vector3d(left.x(), left.y(), z0);
  f.width = w;
  f.height = h;
  f.poly = {f.origin, f.origin + w * f.es, f.origin + w * f.es + h * f.et, f.origin + h * f.et};
  f.color = cv::Vec3f(static_cast<float>(color[0]), static_cast<float>(color[1]),
                      static_cast<float>(color[2]));
  finishFace(f);
  return f;
}

/// The side faces (and the top) of a prism over a convex CCW footprint.
void addPrism(std::vector<Face>& out, const std::vector<Vec2>& foot, double z0, double h,
              Face::Kind kind, const cv::Scalar& color, bool top) {
  double area = 0;
  for (size_t i = 0; i < foot.size(); ++i)
    area += foot[i].x() * foot[(i + 1) % foot.size()].y() -
            foot[(i + 1) % foot.size()].x() * foot[i].y();
  std::vector<Vec2> p = foot;
  if (area < 0) std::reverse(p.begin(), p.end());
  for (size_t i = 0; i < p.size(); ++i) {
    const Vec2& a = p[i];
    const Vec2& b = p[(i + 1) % p.size()];
    const Vec2 d = b - a;
    const double len = d.norm();
    if (len < 1e-6) continue;
    const Vec2 n(d.y() / len, -d.x() / len);  // outward for a CCW footprint
    // Seen from outside, the viewer's right runs from a to b.
    out.push_back(verticalRect(a, n, len, z0, h, kind, color));
  }
  if (top) {
    Face f;
    f.kind = kind;
    f.normal = Vector3d::UnitZ();
    f.origin = Vector3d(p[0].x(), p[0].y(), z0 + h);
    const Vec2 e = (p[1] - p[0]).normalized();
    f.es = Vector3d(e.x(), e.y(), 0);
    f.et = Vector3d(-e.y(), e.x(), 0);
    f.width = f.height = 0;
    for (const auto& q : p) {
      f.poly.emplace_back(q.x(), q.y(), z0 + h);
      f.width = std::max(f.width, (q - p[0]).dot(e));
      f.height = std::max(f.height, (q - p[0]).dot(Vec2(-e.y(), e.x())));
    }
    f.color = cv::Vec3f(static_cast<float>(color[0]) * 1.08f, static_cast<float>(color[1]) * 1.08f,
                        static_cast<float>(color[2]) * 1.08f);
    finishFace(f);
    out.push_back(f);
  }
}

std::vector<Vec2> rect2(const Vec2& c, double hx, double hy, double yaw) {
  const Vec2 ex(std::cos(yaw), std::sin(yaw)), ey(-std::sin(yaw), std::cos(yaw));
  return {c - hx * ex - hy * ey, c + hx * ex - hy * ey, c + hx * ex + hy * ey,
          c - hx * ex + hy * ey};
}

cv::Mat loadTexture(const std::string& path, const std::string& what) {
  cv::Mat t = readImageFile(path, what + ": texture");
  const int longest = std::max(t.cols, t.rows);
  if (longest > 512) {
    cv::resize(t, t, cv::Size(), 512.0 / longest, 512.0 / longest, cv::INTER_AREA);
  }
  return t;
}

inline double frac(double x) {
  return x - std::floor(x);
}

}  // namespace

Renderer::Renderer(const World& world, const SimParams& params)
    : world_(world), params_(params), K_(world.camera.intrinsics()) {
  near_ = world.camera.near;
  far_ = world.camera.far;
  ceiling_ = 2.5;
  if (!world.walls.empty()) {
    ceiling_ = 0;
    for (const auto& w : world.walls) ceiling_ = std::max(ceiling_, w.height);
  }
  frustum_tan_x_ = (0.5 * K_.width + 1) / K_.fx;
  frustum_tan_y_ = (0.5 * K_.height + 1) / K_.fy;

  const cv::Scalar wall_color(200, 212, 222);  // BGR: warm off-white paint
  for (const auto& w : world.walls) {
    const Vec2 d = w.b - w.a;
    const double len = d.norm();
    const Vec2 u = d / len;
    const Vec2 n(-u.y(), u.x());
    const double h = 0.5 * w.thickness;
    // Two long faces and the two end caps (visible at door jambs).
    faces_.push_back(verticalRect(w.b + h * n, n, len, 0, w.height, Face::Kind::Wall, wall_color));
    faces_.push_back(verticalRect(w.a - h * n, -n, len, 0, w.height, Face::Kind::Wall, wall_color));
    faces_.push_back(
        verticalRect(w.b - h * n, u, w.thickness, 0, w.height, Face::Kind::Plain, wall_color));
    faces_.push_back(
        verticalRect(w.a + h * n, -u, w.thickness, 0, w.height, Face::Kind::Plain, wall_color));
  }
  for (const auto& d : world.doors) {
    if (d.open) continue;
    const Vec2 u = (d.b - d.a).normalized();
    const Vec2 n(-u.y(), u.x());
    const cv::Scalar door_color(60, 100, 140);
    const double len = (d.b - d.a).norm();
    faces_.push_back(verticalRect(d.b + 0.02 * n, n, len, 0, 2.0, Face::Kind::Box, door_color));
    faces_.push_back(verticalRect(d.a - 0.02 * n, -n, len, 0, 2.0, Face::Kind::Box, door_color));
  }
  for (const auto& o : world.obstacles) {
    if (o.shape == Obstacle::Shape::Box) {
      addPrism(faces_, rect2(o.centre, 0.5 * o.size_x, 0.5 * o.size_y, o.yaw), 0, o.height,
               Face::Kind::Box, o.color, true);
    } else {
      std::vector<Vec2> foot;
      const int n = 16;
      for (int k = 0; k < n; ++k) {
        const double a = 2 * M_PI * k / n;
        foot.push_back(o.centre + o.radius * Vec2(std::cos(a), std::sin(a)));
      }
      addPrism(faces_, foot, 0, o.height, Face::Kind::Plain, o.color, true);
    }
  }
  for (const auto& l : world.landmarks) {
    const Vec2 n(std::cos(l.yaw), std::sin(l.yaw));
    const Vec2 right(-n.y(), n.x());
    // A few millimetres proud of whatever it is stuck on, so the depth test shows it.
    const Vec2 c = l.position + 0.004 * n;
    const double z0 = l.elevation - 0.5 * l.height;
    Face f = verticalRect(c - 0.5 * l.width * right, n, l.width, z0, l.height, Face::Kind::Texture,
                          cv::Scalar(200, 200, 200));
    textures_.push_back(loadTexture(l.texture, "landmark " + l.id));
    f.texture = static_cast<int>(textures_.size()) - 1;
    f.shade = std::max(f.shade, 0.9f);  // photos are printed matte, lit from the room
    faces_.push_back(f);
    const Vec2 cb = l.position - 0.004 * n;
    Face b = verticalRect(cb + 0.5 * l.width * right, -n, l.width, z0, l.height,
                          l.back_texture.empty() ? Face::Kind::Plain : Face::Kind::Texture,
                          cv::Scalar(150, 165, 175));
    if (!l.back_texture.empty()) {
      textures_.push_back(loadTexture(l.back_texture, "landmark " + l.id + " back"));
      b.texture = static_cast<int>(textures_.size()) - 1;
      b.shade = std::max(b.shade, 0.9f);
    }
    faces_.push_back(b);
  }
  zbuf_.assign(static_cast<size_t>(K_.width) * K_.height, 0.f);
  if (params_.image_noise_std > 0) {
    cv::RNG rng(params_.seed * 7919 + 17);
    for (int i = 0; i < 2; ++i) {
      cv::Mat n(K_.height + 64, K_.width, CV_16SC3);
      rng.fill(n, cv::RNG::NORMAL, 0.0, params_.image_noise_std);
      noise_bank_.push_back(n);
    }
  }
}

void Renderer::drawFloorCeiling(const Eigen::Matrix3d& wRc, const Vector3d& C, cv::Mat& img) {
  const int W = K_.width, H = K_.height;
  const Vector3d du = wRc * Vector3d(1.0 / K_.fx, 0, 0);
  const float fog_k = 0.035f;
  const cv::Vec3f kBackground(90, 90, 90);
  auto shadeColor = [&](const cv::Vec3f& c, double t) {
    const float k = 1.0f / (1.0f + fog_k * static_cast<float>(t));
    return cv::Vec3b(static_cast<uchar>(std::min(255.f, c[0] * k + 0.5f)),
                     static_cast<uchar>(std::min(255.f, c[1] * k + 0.5f)),
                     static_cast<uchar>(std::min(255.f, c[2] * k + 0.5f)));
  };
  // With no camera roll the image rows are level, so the ray's vertical component, hence the
  // distance to the floor (or ceiling), is constant along a row and the hit point moves
  // linearly: the pattern is then evaluated with fixed-point steps instead of per-pixel
  // floor() calls. The general case (a rolled camera) takes the per-pixel path.
  const bool level = std::abs(du.z()) < 1e-12;
  for (int v = 0; v < H; ++v) {
    const Vector3d d0 = wRc * Vector3d(-K_.cx / K_.fx, (v - K_.cy) / K_.fy, 1.0);
    auto* row = img.ptr<cv::Vec3b>(v);
    float* zrow = zbuf_.data() + static_cast<size_t>(v) * W;
    if (level) {
      const double dz = d0.z();
      double t;
      bool floor_hit = false;
      if (dz < -1e-9) {
        t = -C.z() / dz;
        floor_hit = true;
      } else if (dz > 1e-9) {
        t = (ceiling_ - C.z()) / dz;
      } else {
        t = far_;
      }
      if (t >= far_) {
        const cv::Vec3b bg = shadeColor(kBackground, far_);
        for (int u = 0; u < W; ++u) {
          row[u] = bg;
          zrow[u] = static_cast<float>(far_);
        }
        continue;
      }
      std::fill(zrow, zrow + W, static_cast<float>(t));
      // Pattern coordinates in cells: floor tiles 0.5 m (2 cells/m), ceiling tiles 0.6 m.
      const double cells = floor_hit ? 2.0 : 1.0 / 0.6;
      const double px = (C.x() + t * d0.x()) * cells, py = (C.y() + t * d0.y()) * cells;
      const double sx = t * du.x() * cells, sy = t * du.y() * cells;
      constexpr double kOne = 65536.0;
      // Offset keeps the fixed-point values positive (rooms are far smaller than 2^15 cells).
      const double off = 16384.0;
      int64_t X = static_cast<int64_t>(std::floor((px + off) * kOne));
      int64_t Y = static_cast<int64_t>(std::floor((py + off) * kOne));
      const int64_t dX = static_cast<int64_t>(std::llround(sx * kOne));
      const int64_t dY = static_cast<int64_t>(std::llround(sy * kOne));
      if (floor_hit) {
        const cv::Vec3b grout = shadeColor({110, 118, 122}, t),
                        odd = shadeColor({150, 166, 178}, t), even = shadeColor({170, 186, 196}, t);
        const int64_t g = static_cast<int64_t>(0.025 * kOne);
        for (int u = 0; u < W; ++u, X += dX, Y += dY) {
          const int64_t fx = X & 0xFFFF, fy = Y & 0xFFFF;
          row[u] = (fx < g || fy < g) ? grout : ((((X >> 16) + (Y >> 16)) & 1) ? odd : even);
        }
      } else {
        const cv::Vec3b lamp = shadeColor({250, 250, 250}, t),
                        seam = shadeColor({170, 170, 170}, t),
                        plain = shadeColor({215, 218, 218}, t);
        const int64_t g = static_cast<int64_t>(0.02 * kOne);
        for (int u = 0; u < W; ++u, X += dX, Y += dY) {
          const int64_t fx = X & 0xFFFF, fy = Y & 0xFFFF;
          // A lamp panel in one tile of every 5 x 5 (3 m grid).
          const bool is_lamp = ((X >> 16) % 5 == 0) && ((Y >> 16) % 5 == 0);
          row[u] = is_lamp ? lamp : ((fx < g || fy < g) ? seam : plain);
        }
      }
      continue;
    }
    for (int u = 0; u < W; ++u) {
      const double dx = d0.x() + u * du.x(), dy = d0.y() + u * du.y(), dz = d0.z() + u * du.z();
      double t;
      cv::Vec3f col;
      if (dz < -1e-9) {
        t = -C.z() / dz;
        const double px = C.x() + t * dx, py = C.y() + t * dy;
        const double fx = frac(px * 2.0), fy = frac(py * 2.0);
        const bool grout = fx < 0.025 || fy < 0.025;
        const bool odd =
            ((static_cast<long>(std::floor(px * 2.0)) + static_cast<long>(std::floor(py * 2.0))) &
             1) != 0;
        col = grout ? cv::Vec3f(110, 118, 122)
                    : (odd ? cv::Vec3f(150, 166, 178) : cv::Vec3f(170, 186, 196));
      } else if (dz > 1e-9) {
        t = (ceiling_ - C.z()) / dz;
        const double px = C.x() + t * dx, py = C.y() + t * dy;
        const bool lamp = frac(px / 3.0) < 0.2 && frac(py / 3.0) < 0.2;
        const bool seam = frac(px / 0.6) < 0.02 || frac(py / 0.6) < 0.02;
        col = lamp ? cv::Vec3f(250, 250, 250)
                   : (seam ? cv::Vec3f(170, 170, 170) : cv::Vec3f(215, 218, 218));
      } else {
        t = far_;
        col = kBackground;
      }
      if (t > far_) {
        t = far_;
        col = kBackground;
      }
      row[u] = shadeColor(col, t);
      zrow[u] = static_cast<float>(t);
    }
  }
}

void Renderer::drawFace(const Face& f, const Eigen::Matrix3d& cRw, const Vector3d& C,
                        cv::Mat& img) {
  // Cull against the view frustum with the bounding sphere.
  const Vector3d cc = cRw * (f.centre - C);
  if (cc.z() + f.radius < near_ || cc.z() - f.radius > far_) return;
  const double sx = f.radius * std::sqrt(1 + frustum_tan_x_ * frustum_tan_x_);
  const double sy = f.radius * std::sqrt(1 + frustum_tan_y_ * frustum_tan_y_);
  if (std::abs(cc.x()) - sx > frustum_tan_x_ * cc.z()) return;
  if (std::abs(cc.y()) - sy > frustum_tan_y_ * cc.z()) return;
  // Back faces are invisible.
  const Vector3d n = cRw * f.normal;
  const Vector3d o = cRw * (f.origin - C);
  const double d = n.dot(o);  // plane n.X = d in the camera frame
  if (d > -1e-9) return;

  // Clip against the near plane (Sutherland-Hodgman, one plane).
  std::vector<Vector3d> in, poly;
  in.reserve(f.poly.size());
  for (const auto& p : f.poly) in.push_back(cRw * (p - C));
  for (size_t i = 0; i < in.size(); ++i) {
    const Vector3d& a = in[i];
    const Vector3d& b = in[(i + 1) % in.size()];
    const bool ai = a.z() >= near_, bi = b.z() >= near_;
    if (ai) poly.push_back(a);
    if (ai != bi) poly.push_back(a + (b - a) * ((near_ - a.z()) / (b.z() - a.z())));
  }
  if (poly.size() < 3) return;
  std::vector<cv::Point2d> pp;
  double vmin = 1e18, vmax = -1e18;
  for (const auto& p : poly) {
    pp.emplace_back(K_.fx * p.x() / p.z() + K_.cx, K_.fy * p.y() / p.z() + K_.cy);
    vmin = std::min(vmin, pp.back().y);
    vmax = std::max(vmax, pp.back().y);
  }
  const int W = K_.width, H = K_.height;
  const int v0 = std::max(0, static_cast<int>(std::ceil(vmin)));
  const int v1 = std::min(H - 1, static_cast<int>(std::floor(vmax)));
  if (v0 > v1) return;
  ++last_drawn_;

  // 1/z and the face's (s, t) are affine in (u, v) up to the factor z (see renderer.h).
  const double ifx = 1.0 / K_.fx, ify = 1.0 / K_.fy;
  const double A = n.x() * ifx / d, B = n.y() * ify / d,
               Cz = (n.z() - n.x() * K_.cx * ifx - n.y() * K_.cy * ify) / d;
  const Vector3d es = cRw * f.es, et = cRw * f.et;
  const double s0 = es.dot(o), t0 = et.dot(o);
  const double Su = es.x() * ifx, Sv = es.y() * ify,
               Sc = es.z() - es.x() * K_.cx * ifx - es.y() * K_.cy * ify;
  const double Tu = et.x() * ifx, Tv = et.y() * ify,
               Tc = et.z() - et.x() * K_.cx * ifx - et.y() * K_.cy * ify;

  const cv::Mat* tex = f.texture >= 0 ? &textures_[static_cast<size_t>(f.texture)] : nullptr;
  const float fog_k = 0.035f;
  const size_t np = pp.size();
  for (int v = v0; v <= v1; ++v) {
    double xl = 1e18, xr = -1e18;
    for (size_t i = 0; i < np; ++i) {
      const cv::Point2d& a = pp[i];
      const cv::Point2d& b = pp[(i + 1) % np];
      if ((a.y <= v && b.y >= v) || (b.y <= v && a.y >= v)) {
        if (std::abs(b.y - a.y) < 1e-12) {
          xl = std::min(xl, std::min(a.x, b.x));
          xr = std::max(xr, std::max(a.x, b.x));
        } else {
          const double x = a.x + (v - a.y) * (b.x - a.x) / (b.y - a.y);
          xl = std::min(xl, x);
          xr = std::max(xr, x);
        }
      }
    }
    const int u0 = std::max(0, static_cast<int>(std::ceil(xl)));
    const int u1 = std::min(W - 1, static_cast<int>(std::floor(xr)));
    auto* row = img.ptr<cv::Vec3b>(v);
    float* zrow = zbuf_.data() + static_cast<size_t>(v) * W;
    const double iz_row = B * v + Cz, s_row = Sv * v + Sc, t_row = Tv * v + Tc;
    for (int u = u0; u <= u1; ++u) {
      const double iz = A * u + iz_row;
      if (iz <= 0) continue;
      const double z = 1.0 / iz;
      if (z >= zrow[u]) continue;
      const double s = z * (Su * u + s_row) - s0;
      const double t = z * (Tu * u + t_row) - t0;
      cv::Vec3f col;
      float k = f.shade;
      switch (f.kind) {
        case Face::Kind::Texture: {
          const double x = std::clamp(s / f.width, 0.0, 1.0) * tex->cols - 0.5;
          const double y = (1.0 - std::clamp(t / f.height, 0.0, 1.0)) * tex->rows - 0.5;
          const int xi = std::clamp(static_cast<int>(std::floor(x)), 0, tex->cols - 2);
          const int yi = std::clamp(static_cast<int>(std::floor(y)), 0, tex->rows - 2);
          const float ax = static_cast<float>(std::clamp(x - xi, 0.0, 1.0));
          const float ay = static_cast<float>(std::clamp(y - yi, 0.0, 1.0));
          const auto* r0 = tex->ptr<cv::Vec3b>(yi);
          const auto* r1 = tex->ptr<cv::Vec3b>(yi + 1);
          for (int c = 0; c < 3; ++c)
            col[c] = (1 - ay) * ((1 - ax) * r0[xi][c] + ax * r0[xi + 1][c]) +
                     ay * ((1 - ax) * r1[xi][c] + ax * r1[xi + 1][c]);
          break;
        }
        case Face::Kind::Wall: {
          col = f.color;
          if (t < 0.10) {
            k *= 0.55f;  // skirting board
          } else if (t > 0.95 && t < 1.0) {
            k *= 0.8f;  // dado rail
          } else if (frac(s / 1.2) < 0.012) {
            k *= 0.85f;  // panel seams
          } else if (t < 0.95) {
            col = cv::Vec3f(175, 190, 160);  // lower half painted another colour
          }
          k *= static_cast<float>(0.9 + 0.1 * std::min(1.0, t / f.height));
          break;
        }
        case Face::Kind::Box: {
          col = f.color;
          const double e = 0.02;
          if (s < e || s > f.width - e || t < e || t > f.height - e)
            k *= 0.6f;  // edges
          else if (f.height > 1.0 && frac(t / 0.4) < 0.03)
            k *= 0.75f;  // drawers / shelves on tall furniture
          break;
        }
        case Face::Kind::Person: {
          col = t < 0.85 ? cv::Vec3f(70, 55, 45) : f.color;  // trousers, shirt
          break;
        }
        case Face::Kind::Plain:
          col = f.color;
          break;
      }
      k /= (1.0f + fog_k * static_cast<float>(z));
      zrow[u] = static_cast<float>(z);
      row[u] = cv::Vec3b(static_cast<uchar>(std::min(255.f, col[0] * k + 0.5f)),
                         static_cast<uchar>(std::min(255.f, col[1] * k + 0.5f)),
                         static_cast<uchar>(std::min(255.f, col[2] * k + 0.5f)));
    }
  }
}

void Renderer::render(const hw::Pose2D& wMr, double t, const std::vector<PedestrianState>& peds,
                      bool degrade, std::mt19937_64& rng, cv::Mat& out) {
  Eigen::Isometry3d wTr = Eigen::Isometry3d::Identity();
  wTr.translation() = Vector3d(wMr.x, wMr.y, 0);
  wTr.linear() = Eigen::AngleAxisd(wMr.theta, Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Isometry3d wMc = wTr * world_.camera.rMc();
  const Eigen::Matrix3d wRc = wMc.linear();
  const Eigen::Matrix3d cRw = wRc.transpose();
  const Vector3d C = wMc.translation();

  out.create(K_.height, K_.width, CV_8UC3);
  last_drawn_ = 0;
  drawFloorCeiling(wRc, C, out);
  for (const auto& f : faces_) drawFace(f, cRw, C, out);
  // Pedestrians: a shaded box facing their walking direction.
  std::vector<Face> pf;
  for (size_t i = 0; i < peds.size() && i < world_.pedestrians.size(); ++i) {
    const auto& p = peds[i];
    const double yaw = p.velocity.norm() > 1e-6 ? std::atan2(p.velocity.y(), p.velocity.x()) : 0;
    pf.clear();
    // Body (legs and torso) and a smaller head on top.
    const double h = world_.pedestrians[i].height;
    addPrism(pf, rect2(p.position, 0.6 * p.radius, p.radius, yaw), 0, h - 0.25, Face::Kind::Person,
             world_.pedestrians[i].color, true);
    addPrism(pf, rect2(p.position, 0.09, 0.1, yaw), h - 0.25, 0.25, Face::Kind::Plain,
             cv::Scalar(140, 170, 210), true);
    for (const auto& f : pf) drawFace(f, cRw, C, out);
  }

  // Lighting: global brightness, slow variation, per-frame jitter; then pixel noise and blur.
  const auto& L = world_.lighting;
  double b = L.brightness * (1.0 + L.variation * std::sin(2 * M_PI * t / L.period));
  if (degrade && params_.brightness_jitter > 0) {
    std::normal_distribution<double> g(0.0, params_.brightness_jitter);
    b *= std::max(0.2, 1.0 + g(rng));
  }
  const bool noise = degrade && !noise_bank_.empty();
  if (noise) {
    const size_t which = rng() % noise_bank_.size();
    const int off = static_cast<int>(rng() % 64);
    const int bi = static_cast<int>(std::lround(b * 256));
    for (int v = 0; v < out.rows; ++v) {
      uchar* p = out.ptr<uchar>(v);
      const short* nz = noise_bank_[which].ptr<short>(v + off);
      for (int i = 0; i < out.cols * 3; ++i)
        p[i] = cv::saturate_cast<uchar>(((p[i] * bi) >> 8) + nz[i]);
    }
  } else if (std::abs(b - 1.0) > 1e-6) {
    out.convertTo(out, CV_8UC3, b);
  }
  if (degrade && params_.blur_sigma > 0) cv::GaussianBlur(out, out, cv::Size(), params_.blur_sigma);
}

}  // namespace sketchnav::sim
