#include "sketchnav/sim/map_render.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "geometry.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/input_file.h"

namespace sketchnav::sim {
namespace {
std::string shortClass(const std::string& c) {
  // "God-Morgon-Red-Grapefruit-Juice" -> "God-Morgon-Red..." keeps labels readable.
  return c.size() > 18 ? c.substr(0, 16) + ".." : c;
}
}  // namespace

MapCanvas::MapCanvas(const World& w, double px_per_m, double margin_m, bool labels)
    : scale_(px_per_m) {
  Vec2 lo(1e18, 1e18), hi(-1e18, -1e18);
  auto grow = [&](const Vec2& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  };
  for (const auto& p : w.floor) grow(p);
  for (const auto& x : w.walls) {
    grow(x.a);
    grow(x.b);
  }
  if (lo.x() > hi.x()) lo = hi = Vec2(0, 0);
  origin_ = Vec2(lo.x() - margin_m, hi.y() + margin_m);
  const int W = static_cast<int>(std::ceil((hi.x() - lo.x() + 2 * margin_m) * scale_));
  const int H = static_cast<int>(std::ceil((hi.y() - lo.y() + 2 * margin_m) * scale_));
  image_ = cv::Mat(H, W, CV_8UC3, cv::Scalar(235, 235, 235));

  auto poly = [&](const std::vector<Vec2>& pts) {
    std::vector<cv::Point> out;
    for (const auto& p : pts) out.push_back(toPixel(p));
    return out;
  };
  cv::fillPoly(image_, std::vector<std::vector<cv::Point>>{poly(w.floor)},
               cv::Scalar(255, 255, 255), cv::LINE_AA);
  const cv::Scalar region_tints[] = {{245, 235, 225}, {225, 245, 235}, {235, 228, 248}};
  for (size_t i = 0; i < w.regions.size(); ++i)
    cv::fillPoly(image_, std::vector<std::vector<cv::Point>>{poly(w.regions[i].polygon)},
                 region_tints[i % 3], cv::LINE_AA);
  // Faint 1 m grid for scale.
  for (double x = std::floor(lo.x()); x <= hi.x(); x += 1.0)
    cv::line(image_, toPixel({x, lo.y()}), toPixel({x, hi.y()}), cv::Scalar(228, 228, 228), 1);
  for (double y = std::floor(lo.y()); y <= hi.y(); y += 1.0)
    cv::line(image_, toPixel({lo.x(), y}), toPixel({hi.x(), y}), cv::Scalar(228, 228, 228), 1);
  if (labels)
    for (const auto& r : w.regions) {
      // The name goes just above the region's lowest edge, where furniture rarely stands.
      Vec2 c(0, 0);
      double bottom = 1e18;
      for (const auto& p : r.polygon) {
        c += p;
        bottom = std::min(bottom, p.y());
      }
      c /= static_cast<double>(r.polygon.size());
      int base = 0;
      const cv::Size ts = cv::getTextSize(r.name, cv::FONT_HERSHEY_SIMPLEX, 0.5, 1, &base);
      drawText({c.x() - 0.5 * ts.width / scale_, bottom + 0.25}, r.name, cv::Scalar(120, 120, 120),
               0.5);
    }
  for (const auto& o : w.obstacles) {
    if (o.shape == Obstacle::Shape::Box) {
      const auto pts = poly(geom::rectangle(o.centre, 0.5 * o.size_x, 0.5 * o.size_y, o.yaw));
      cv::fillConvexPoly(image_, pts, o.color, cv::LINE_AA);
      cv::polylines(image_, pts, true, cv::Scalar(70, 70, 70), 1, cv::LINE_AA);
    } else {
      cv::circle(image_, toPixel(o.centre), static_cast<int>(std::lround(o.radius * scale_)),
                 o.color, cv::FILLED, cv::LINE_AA);
      cv::circle(image_, toPixel(o.centre), static_cast<int>(std::lround(o.radius * scale_)),
                 cv::Scalar(70, 70, 70), 1, cv::LINE_AA);
    }
    if (labels) drawText(o.centre + Vec2(-0.3, -0.08), o.name, cv::Scalar(60, 60, 60), 0.33);
  }
  for (const auto& x : w.walls)
    cv::line(image_, toPixel(x.a), toPixel(x.b), cv::Scalar(40, 40, 40),
             std::max(2, static_cast<int>(std::lround(x.thickness * scale_))), cv::LINE_AA);
  for (const auto& d : w.doors) {
    const cv::Scalar c = d.open ? cv::Scalar(40, 120, 200) : cv::Scalar(30, 60, 130);
    if (d.open) {
      // A door leaf swung open: a line from the hinge and the arc it sweeps.
      const Vec2 u = d.b - d.a;
      const double len = u.norm();
      const Vec2 n(-u.y() / len, u.x() / len);
      cv::line(image_, toPixel(d.a), toPixel(d.a + len * n), c, 1, cv::LINE_AA);
      const double a0 = std::atan2(-u.y(), u.x()) * 180 / M_PI;
      const double a1 = std::atan2(-n.y(), n.x()) * 180 / M_PI;
      cv::ellipse(image_, toPixel(d.a), cv::Size(int(len * scale_), int(len * scale_)), 0, a0, a1,
                  c, 1, cv::LINE_AA);
    } else {
      cv::line(image_, toPixel(d.a), toPixel(d.b), c, 4, cv::LINE_AA);
    }
  }
  for (const auto& p : w.pedestrians) {
    std::vector<Vec2> path = p.path;
    if (p.loop) path.push_back(p.path.front());
    drawPolyline(path, cv::Scalar(160, 120, 220), true, 1);
  }
  for (const auto& l : w.landmarks) {
    // The photo's face as a short thick line, its normal as a tick, and the star.
    const Vec2 n(std::cos(l.yaw), std::sin(l.yaw)), r(-n.y(), n.x());
    cv::line(image_, toPixel(l.position - 0.5 * l.width * r),
             toPixel(l.position + 0.5 * l.width * r), cv::Scalar(0, 140, 255), 3, cv::LINE_AA);
    cv::line(image_, toPixel(l.position), toPixel(l.position + 0.35 * n), cv::Scalar(0, 140, 255),
             1, cv::LINE_AA);
    drawStar(l.position, cv::Scalar(0, 0, 220), 9);
    if (labels) {
      // Label beside the star on the side the photo faces, kept inside the image.
      const std::string text = l.id + " " + shortClass(l.class_name);
      int base = 0;
      const cv::Size ts = cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, 0.36, 1, &base);
      cv::Point p = toPixel(l.position + 0.45 * n);
      p.x = std::clamp(p.x - 10, 2, image_.cols - ts.width - 2);
      p.y = std::clamp(p.y + ts.height / 2, ts.height + 2, image_.rows - 3);
      cv::putText(image_, text, p, cv::FONT_HERSHEY_SIMPLEX, 0.36, cv::Scalar(0, 0, 160), 1,
                  cv::LINE_AA);
    }
  }
  drawStart({w.start.x, w.start.y});
  drawGoal(w.goal.centre, w.goal.radius);
}

cv::Point2d MapCanvas::toPixelF(const Eigen::Vector2d& p) const {
  return {(p.x() - origin_.x()) * scale_, (origin_.y() - p.y()) * scale_};
}
cv::Point MapCanvas::toPixel(const Eigen::Vector2d& p) const {
  const cv::Point2d q = toPixelF(p);
  return {static_cast<int>(std::lround(q.x)), static_cast<int>(std::lround(q.y))};
}

void MapCanvas::drawPolyline(const std::vector<Eigen::Vector2d>& pts, cv::Scalar color, bool dashed,
                             int thickness) {
  if (pts.size() < 2) return;
  if (!dashed) {
    std::vector<cv::Point> q;
    for (const auto& p : pts) q.push_back(toPixel(p));
    cv::polylines(image_, q, false, color, thickness, cv::LINE_AA);
    return;
  }
  // Dashes of ~8 px on, 6 px off, continuing across vertices.
  const double on = 8.0 / scale_, off = 6.0 / scale_;
  bool drawing = true;
  double left = on;  // what remains of the current dash or gap
  for (size_t i = 1; i < pts.size(); ++i) {
    const Vec2 a = pts[i - 1], b = pts[i];
    const double len = (b - a).norm();
    if (len < 1e-9) continue;
    const Vec2 u = (b - a) / len;
    double s = 0;
    while (len - s > 1e-9) {
      const double step = std::min(len - s, left);
      if (drawing)
        cv::line(image_, toPixel(a + s * u), toPixel(a + (s + step) * u), color, thickness,
                 cv::LINE_AA);
      s += step;
      left -= step;
      if (left <= 1e-9) {
        drawing = !drawing;
        left = drawing ? on : off;
      }
    }
  }
}

void MapCanvas::drawPoses(const std::vector<hw::Pose2D>& poses, cv::Scalar color, bool dashed,
                          int thickness) {
  std::vector<Eigen::Vector2d> pts;
  for (const auto& p : poses) pts.emplace_back(p.x, p.y);
  drawPolyline(pts, color, dashed, thickness);
}

void MapCanvas::drawStart(const Eigen::Vector2d& p, cv::Scalar color) {
  cv::circle(image_, toPixel(p), 7, color, cv::FILLED, cv::LINE_AA);
}

void MapCanvas::drawGoal(const Eigen::Vector2d& p, double radius_m, cv::Scalar color) {
  const int r = std::max(6, static_cast<int>(std::lround(radius_m * scale_)));
  cv::circle(image_, toPixel(p), r, color, 2, cv::LINE_AA);
  cv::circle(image_, toPixel(p), std::max(3, r / 2), color, 2, cv::LINE_AA);
}

void MapCanvas::drawStar(const Eigen::Vector2d& p, cv::Scalar color, int size_px) {
  std::vector<cv::Point> pts;
  const cv::Point2d c = toPixelF(p);
  for (int k = 0; k < 10; ++k) {
    const double r = (k % 2 == 0) ? size_px : 0.42 * size_px;
    const double a = -M_PI / 2 + k * M_PI / 5;
    pts.emplace_back(static_cast<int>(std::lround(c.x + r * std::cos(a))),
                     static_cast<int>(std::lround(c.y + r * std::sin(a))));
  }
  cv::fillPoly(image_, std::vector<std::vector<cv::Point>>{pts}, color, cv::LINE_AA);
}

void MapCanvas::drawRobot(const hw::Pose2D& pose, double radius_m, cv::Scalar color) {
  const Vec2 c(pose.x, pose.y);
  cv::circle(image_, toPixel(c), std::max(2, static_cast<int>(std::lround(radius_m * scale_))),
             color, 2, cv::LINE_AA);
  cv::line(image_, toPixel(c),
           toPixel(c + radius_m * 1.5 * Vec2(std::cos(pose.theta), std::sin(pose.theta))), color, 2,
           cv::LINE_AA);
}

void MapCanvas::drawText(const Eigen::Vector2d& p, const std::string& text, cv::Scalar color,
                         double scale) {
  cv::putText(image_, text, toPixel(p), cv::FONT_HERSHEY_SIMPLEX, scale, color, 1, cv::LINE_AA);
}

void MapCanvas::drawLegend(const std::vector<std::pair<std::string, cv::Scalar>>& entries) {
  int width = 0;
  for (const auto& e : entries) {
    int base = 0;
    width =
        std::max(width, cv::getTextSize(e.first, cv::FONT_HERSHEY_SIMPLEX, 0.45, 1, &base).width);
  }
  // On a white card so it stays readable over walls and furniture.
  const cv::Rect card(4, 4, width + 44, 18 * static_cast<int>(entries.size()) + 8);
  cv::rectangle(image_, card, cv::Scalar(255, 255, 255), cv::FILLED);
  cv::rectangle(image_, card, cv::Scalar(150, 150, 150), 1);
  int y = 20;
  for (const auto& [text, color] : entries) {
    cv::line(image_, {10, y - 4}, {34, y - 4}, color, 2, cv::LINE_AA);
    cv::putText(image_, text, {40, y}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(30, 30, 30), 1,
                cv::LINE_AA);
    y += 18;
  }
}

void MapCanvas::save(const std::string& path) const {
  // Encoded in memory and written whole (temp file + rename): a run killed while saving its
  // trajectory.png leaves no half image behind.
  bool ok = false;
  std::vector<uchar> bytes;
  try {
    ok = cv::imencode(std::filesystem::path(path).extension().string(), image_, bytes);
  } catch (const cv::Exception& e) {
    throw RuntimeError("cannot write map image '" + path + "': " + e.what());
  }
  if (!ok) throw RuntimeError("cannot write map image '" + path + "'");
  writeFileAtomically(path, std::string(bytes.begin(), bytes.end()), "map image");
}

}  // namespace sketchnav::sim
