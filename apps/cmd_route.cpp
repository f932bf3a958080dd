// sketchnav route: convert a sketch into its route (path sections): a table, --json, or a
// PNG drawn over the sketch (what the robot will follow, for a person to check).
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdio>
#include <iostream>

#include "cli.h"
#include "sketchnav/core/error.h"
#include "sketchnav/mapsketch/io.h"
#include "sketchnav/mapsketch/route.h"

namespace sketchnav::app {
namespace {
using namespace mapsketch;

std::string f1(double v, const char* fmt = "%.1f") {
  char b[32];
  std::snprintf(b, sizeof b, fmt, v);
  std::string s = b;
  // "-0.0" reads like a sign error to a person; it is just rounding.
  if (s.find_first_not_of("-0.") == std::string::npos && s[0] == '-') s = s.substr(1);
  return s;
}
double deg(double rad) {
  return rad * 180.0 / M_PI;
}

void printTable(const Sketch& s, const Route& r, const std::string& file) {
  std::cout << "sketch    " << file << (s.name.empty() ? "" : "  (" + s.name + ")") << "\n"
            << "scale     " << f1(r.scale_m_per_px * 100, "%.3f")
            << " m per 100 px, distance residual " << f1(100 * r.scale_residual)
            << " % (RMS, relative)\n"
            << "route     " << r.sections.size() << " sections, " << f1(r.total_length_m) << " m, "
            << r.guide_points_m.size() << " guide points from " << s.path.size()
            << " drawn points\n";
  if (r.goal_place.kind == mapsketch::GoalPlace::Kind::Doorway)
    std::cout << "goal      a doorway: the robot stops " << f1(r.goal_place.standoff_m, "%.2f")
              << " m in front of the opening its laser finds near the drawn goal\n";
  std::cout << "\n";
  std::printf("%-4s %-27s %7s %8s %7s  %s\n", "sec", "from -> to [m]", "len[m]", "head[deg]",
              "turn", "landmarks (#order class id side range@along)");
  for (const auto& sec : r.sections) {
    const std::string span = "(" + f1(sec.start_m.x()) + "," + f1(sec.start_m.y()) + ")->(" +
                             f1(sec.end_m.x()) + "," + f1(sec.end_m.y()) + ")";
    std::string lms;
    for (const auto& l : sec.landmarks)
      lms += (lms.empty() ? "" : "; ") +
             ("#" + std::to_string(l.order + 1) + " " + l.class_name + " " + l.id + " " +
              sideName(l.side) + " " + f1(l.range_m) + "m@" + f1(l.along_m) + "m");
    std::printf("%-4d %-27s %7.1f %8.0f %+7.0f  %s\n", sec.index, span.c_str(), sec.length_m,
                deg(sec.heading_rad), deg(sec.heading_change_rad), lms.empty() ? "-" : lms.c_str());
  }
  for (const auto& w : r.warnings) std::cout << "warning: " << w << "\n";
}

// Draws the sketch as the user drew it and, over it, the route the robot will follow.
void drawPng(const Sketch& s, const Route& r, const std::string& path) {
  const double k = std::min(1.0, 1400.0 / std::max(s.canvas_width, s.canvas_height)) * 1.0;
  const int W = static_cast<int>(std::ceil(s.canvas_width * k)),
            H = static_cast<int>(std::ceil(s.canvas_height * k));
  const int footer = 28;
  cv::Mat img(H + footer, W, CV_8UC3, cv::Scalar(255, 255, 255));
  auto P = [&](const Eigen::Vector2d& p) {
    return cv::Point(cvRound(p.x() * k), cvRound(p.y() * k));
  };
  // Route frame (metres, y up, origin at start) back to the canvas, for guide points.
  auto fromM = [&](const Eigen::Vector2d& m) {
    return Eigen::Vector2d(s.start.x() + m.x() / r.scale_m_per_px,
                           s.start.y() - m.y() / r.scale_m_per_px);
  };
  const auto font = cv::FONT_HERSHEY_SIMPLEX;
  cv::rectangle(img, {0, 0}, {W - 1, H - 1}, cv::Scalar(200, 200, 200), 1);
  std::map<std::string, int> order;
  for (const auto& sec : r.sections)
    for (const auto& l : sec.landmarks) order[l.id] = l.order;
  for (const auto& l : s.landmarks) {
    const cv::Rect rc(P({l.rect.x, l.rect.y}), P({l.rect.x + l.rect.w, l.rect.y + l.rect.h}));
    cv::rectangle(img, rc, cv::Scalar(245, 225, 200), cv::FILLED);
    cv::rectangle(img, rc, cv::Scalar(160, 90, 30), 2);
    const std::string label = "#" + std::to_string(order[l.id] + 1) + " " + l.class_name;
    int base = 0;
    const int tw = cv::getTextSize(label, font, 0.42, 1, &base).width;
    const cv::Point at(std::max(2, std::min(rc.x + 2, W - tw - 2)), std::max(12, rc.y - 5));
    cv::putText(img, label, at, font, 0.42, cv::Scalar(120, 60, 20), 1, cv::LINE_AA);
    cv::putText(img, l.id + "  " + f1(l.distance_m) + " m", rc.tl() + cv::Point(4, 14), font, 0.38,
                cv::Scalar(120, 60, 20), 1, cv::LINE_AA);
  }
  std::vector<cv::Point> raw;
  for (const auto& p : s.path) raw.push_back(P(p));
  cv::polylines(img, raw, false, cv::Scalar(170, 170, 170), 2, cv::LINE_AA);
  const cv::Scalar colours[2] = {cv::Scalar(40, 140, 40), cv::Scalar(30, 100, 220)};
  for (const auto& sec : r.sections) {
    const cv::Point a = P(fromM(sec.start_m)), b = P(fromM(sec.end_m));
    cv::arrowedLine(img, a, b, colours[sec.index % 2], 2, cv::LINE_AA, 0,
                    std::min(0.3, 14.0 / std::max(1.0, cv::norm(b - a))));
    for (const auto& l : sec.landmarks)  // where the robot expects to pass each landmark
      cv::line(img, P(fromM(sec.start_m + (sec.end_m - sec.start_m).normalized() * l.along_m)),
               P(fromM(l.position_m)), colours[sec.index % 2], 1, cv::LINE_AA);
  }
  cv::circle(img, P(s.start), 13, cv::Scalar(0, 160, 0), 3, cv::LINE_AA);
  cv::putText(img, "start", P(s.start) + cv::Point(8, 18), font, 0.45, cv::Scalar(0, 120, 0), 1,
              cv::LINE_AA);
  cv::circle(img, P(s.goal), 13, cv::Scalar(0, 0, 200), 3, cv::LINE_AA);
  const std::string goal_label =
      r.goal_place.kind == mapsketch::GoalPlace::Kind::Doorway
          ? "goal: " + f1(r.goal_place.standoff_m, "%.1f") + " m before the door"
          : std::string("goal");
  // A long label by the right edge goes to the goal's left, so it stays on the picture.
  const int label_w = cv::getTextSize(goal_label, font, 0.45, 1, nullptr).width;
  const cv::Point goal_at =
      P(s.goal) +
      (P(s.goal).x + 8 + label_w > W - 4 ? cv::Point(-8 - label_w, 28) : cv::Point(8, 18));
  cv::putText(img, goal_label, goal_at, font, 0.45, cv::Scalar(0, 0, 170), 1, cv::LINE_AA);
  for (size_t i = 0; i < r.guide_points_m.size(); ++i) {
    const cv::Point c = P(fromM(r.guide_points_m[i]));
    cv::circle(img, c, 9, cv::Scalar(255, 255, 255), cv::FILLED, cv::LINE_AA);
    cv::circle(img, c, 9, cv::Scalar(60, 60, 60), 1, cv::LINE_AA);
    const std::string n = std::to_string(i);
    cv::putText(img, n, c + cv::Point(n.size() > 1 ? -7 : -4, 4), font, 0.38, cv::Scalar(0, 0, 0),
                1, cv::LINE_AA);
  }
  const std::string foot =
      (s.name.empty() ? std::string("sketch") : s.name) + ": " + std::to_string(r.sections.size()) +
      " sections, " + f1(r.total_length_m) + " m, scale " + f1(r.scale_m_per_px * 100, "%.2f") +
      " m/100px, residual " + f1(100 * r.scale_residual) + " %";
  cv::putText(img, foot, {6, H + 19}, font, 0.45, cv::Scalar(40, 40, 40), 1, cv::LINE_AA);
  if (!cv::imwrite(path, img)) throw RuntimeError("sketchnav route: cannot write '" + path + "'");
}

int runRoute(const std::vector<std::string>& argv_in, GlobalOptions& g) {
  Args args("route", "convert a sketch into its route (path sections)",
            "SKETCH [--json] [-o route.png]");
  args.positionals("SKETCH", "a .sketch.json file", 1, 1)
      .option("png", "also draw the route over the sketch into this PNG file (-o FILE is the same)")
      .option("landmarks",
              "check the sketch's classes against this landmark set (folder per class)");
  std::vector<std::string> argv;
  for (size_t i = 0; i < argv_in.size(); ++i) {
    if (argv_in[i] == "-o") {
      if (i + 1 >= argv_in.size()) throw InputError("sketchnav route: -o needs a file name");
      argv.push_back("--png");
    } else {
      argv.push_back(argv_in[i]);
    }
  }
  if (!args.parse(argv)) return 0;
  RouteParams params;
  applyConfig(params, g.config, "route");
  g.config.requireAllUsed();
  const std::string file = args.positional().front();
  const Sketch s = loadSketch(file);
  if (args.has("landmarks")) validateClasses(s, landmarkClasses(args.get("landmarks")), file);
  const Route r = toRoute(s, params);
  if (args.has("png")) drawPng(s, r, args.get("png"));
  if (g.json) {
    Json j = routeToJson(r);
    j["sketch"] = file;
    if (args.has("png")) j["png"] = args.get("png");
    printJson(j);
  } else {
    printTable(s, r, file);
    if (args.has("png")) std::cout << "drawn to  " << args.get("png") << "\n";
  }
  return 0;
}
const CommandRegistration reg("route", "convert a sketch into its route (path sections)", runRoute);
}  // namespace
}  // namespace sketchnav::app
