#include "sketchnav/run/plot.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace sketchnav::run {
namespace {

// "Nice" tick step for a range (1, 2, 5 x 10^k), about `n` ticks.
double niceStep(double range, int n) {
  const double raw = range / std::max(1, n);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (raw <= m * mag) return m * mag;
  return 10 * mag;
}

std::string fmt(double v, double step) {
  char b[32];
  const int dec =
      step >= 1 ? 0 : std::min(4, static_cast<int>(std::ceil(-std::log10(step) - 1e-9)));
  std::snprintf(b, sizeof b, "%.*f", dec, v);
  return b;
}

}  // namespace

cv::Scalar plotColor(int i) {
  static const cv::Scalar c[] = {{180, 100, 30}, {40, 120, 240}, {60, 160, 60},  {40, 40, 200},
                                 {160, 80, 160}, {30, 160, 200}, {120, 120, 120}};
  return c[static_cast<size_t>(i) % (sizeof c / sizeof c[0])];
}

cv::Mat drawLinePlot(const PlotSpec& spec, const std::vector<PlotSeries>& series) {
  cv::Mat img(spec.height, spec.width, CV_8UC3, cv::Scalar(255, 255, 255));
  const int left = 70, right = 20, top = 36, bottom = 50;
  const cv::Rect area(left, top, spec.width - left - right, spec.height - top - bottom);
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (const auto& s : series)
    for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i])) continue;
      x0 = std::min(x0, s.x[i]), x1 = std::max(x1, s.x[i]);  // the axis even without y data
      if (!std::isfinite(s.y[i])) continue;
      y0 = std::min(y0, s.y[i]), y1 = std::max(y1, s.y[i]);
    }
  if (x0 > x1) x0 = 0, x1 = 1;
  if (y0 > y1) y0 = 0, y1 = 1;
  if (std::isfinite(spec.y_min)) y0 = spec.y_min;
  if (std::isfinite(spec.y_max)) y1 = spec.y_max;
  if (x1 - x0 < 1e-12) x0 -= 0.5, x1 += 0.5;
  if (y1 - y0 < 1e-12) y0 -= 0.5, y1 += 0.5;
  const double xs = niceStep(x1 - x0, 6), ys = niceStep(y1 - y0, 5);
  if (!std::isfinite(spec.y_min)) y0 = std::floor(y0 / ys) * ys;
  if (!std::isfinite(spec.y_max)) y1 = std::ceil(y1 / ys) * ys;
  const double xpad = 0.04 * (x1 - x0);
  x0 -= xpad, x1 += xpad;
  auto px = [&](double x, double y) {
    return cv::Point(static_cast<int>(area.x + (x - x0) / (x1 - x0) * area.width),
                     static_cast<int>(area.y + area.height - (y - y0) / (y1 - y0) * area.height));
  };
  const cv::Scalar ink(40, 40, 40), grid(225, 225, 225);
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  // Grid and ticks.
  for (double y = std::ceil(y0 / ys) * ys; y <= y1 + 1e-9; y += ys) {
    const cv::Point p = px(x0, y);
    cv::line(img, {area.x, p.y}, {area.x + area.width, p.y}, grid, 1);
    cv::line(img, {area.x - 5, p.y}, {area.x, p.y}, ink, 1);
    const std::string t = fmt(y, ys);
    int base = 0;
    const cv::Size sz = cv::getTextSize(t, font, 0.4, 1, &base);
    cv::putText(img, t, {area.x - 8 - sz.width, p.y + 4}, font, 0.4, ink, 1, cv::LINE_AA);
  }
  for (double x = std::ceil(x0 / xs) * xs; x <= x1 + 1e-9; x += xs) {
    const cv::Point p = px(x, y0);
    cv::line(img, {p.x, area.y}, {p.x, area.y + area.height}, grid, 1);
    cv::line(img, {p.x, area.y + area.height}, {p.x, area.y + area.height + 5}, ink, 1);
    const std::string t = fmt(x, xs);
    int base = 0;
    const cv::Size sz = cv::getTextSize(t, font, 0.4, 1, &base);
    cv::putText(img, t, {p.x - sz.width / 2, area.y + area.height + 20}, font, 0.4, ink, 1,
                cv::LINE_AA);
  }
  cv::rectangle(img, area, ink, 1);
  if (std::isfinite(spec.marker_x)) {
    const int u = px(spec.marker_x, y0).x;
    for (int v = area.y; v < area.y + area.height; v += 8)
      cv::line(img, {u, v}, {u, std::min(v + 4, area.y + area.height)}, {0, 0, 0}, 1);
  }
  // Labels.
  int base = 0;
  cv::Size sz = cv::getTextSize(spec.title, font, 0.55, 1, &base);
  cv::putText(img, spec.title, {(spec.width - sz.width) / 2, 22}, font, 0.55, ink, 1, cv::LINE_AA);
  sz = cv::getTextSize(spec.x_label, font, 0.45, 1, &base);
  cv::putText(img, spec.x_label, {area.x + (area.width - sz.width) / 2, spec.height - 10}, font,
              0.45, ink, 1, cv::LINE_AA);
  {  // rotated y label
    sz = cv::getTextSize(spec.y_label, font, 0.45, 1, &base);
    cv::Mat t(sz.height + base + 4, sz.width + 4, CV_8UC3, cv::Scalar(255, 255, 255));
    cv::putText(t, spec.y_label, {2, sz.height + 2}, font, 0.45, ink, 1, cv::LINE_AA);
    cv::Mat r;
    cv::rotate(t, r, cv::ROTATE_90_COUNTERCLOCKWISE);
    const int yy = std::max(0, area.y + (area.height - r.rows) / 2);
    if (yy + r.rows <= img.rows && r.cols + 4 <= left)
      r.copyTo(img(cv::Rect(4, yy, r.cols, r.rows)));
  }
  // Series.
  for (const auto& s : series) {
    cv::Point prev(-1, -1);
    for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) {
        prev = {-1, -1};
        continue;
      }
      const cv::Point p = px(s.x[i], s.y[i]);
      if (prev.x >= 0) cv::line(img, prev, p, s.color, 2, cv::LINE_AA);
      cv::circle(img, p, 4, s.color, cv::FILLED, cv::LINE_AA);
      prev = p;
    }
  }
  // Legend (top right, inside the axes).
  int lw = 0;
  for (const auto& s : series)
    lw = std::max(lw, cv::getTextSize(s.label, font, 0.4, 1, &base).width);
  const int lx = area.x + area.width - lw - 40, ly = area.y + 8;
  if (!series.empty()) {
    cv::rectangle(img, {lx - 6, ly - 4},
                  {area.x + area.width - 6, ly + 18 * static_cast<int>(series.size())},
                  cv::Scalar(255, 255, 255), cv::FILLED);
    cv::rectangle(img, {lx - 6, ly - 4},
                  {area.x + area.width - 6, ly + 18 * static_cast<int>(series.size())}, grid, 1);
  }
  for (size_t i = 0; i < series.size(); ++i) {
    const int y = ly + 8 + 18 * static_cast<int>(i);
    cv::line(img, {lx, y}, {lx + 22, y}, series[i].color, 2, cv::LINE_AA);
    cv::putText(img, series[i].label, {lx + 28, y + 4}, font, 0.4, ink, 1, cv::LINE_AA);
  }
  return img;
}

cv::Mat drawConfusionMatrix(const ConfusionSpec& spec) {
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  const double fs = 0.4;
  const int cell = 18;
  auto textWidth = [&](const std::string& t, double scale) {
    int base = 0;
    return cv::getTextSize(t, font, scale, 1, &base).width;
  };
  int row_w = 0, col_h = 0, note_w = 0;
  for (const auto& r : spec.rows) row_w = std::max(row_w, textWidth(r, fs));
  for (const auto& c : spec.cols) col_h = std::max(col_h, textWidth(c, fs));
  for (const auto& n : spec.row_notes) note_w = std::max(note_w, textWidth(n, fs));
  const int nr = static_cast<int>(spec.rows.size()), nc = static_cast<int>(spec.cols.size());
  const int left = row_w + 12, top = col_h + 40, right = note_w + 16, bottom = 30;
  const int width = std::max(left + nc * cell + right, textWidth(spec.title, 0.5) + 20);
  cv::Mat img(top + nr * cell + bottom, width, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::putText(img, spec.title, {10, 20}, font, 0.5, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  // Column labels: drawn horizontally on a strip, then turned to read bottom-up.
  for (int c = 0; c < nc; ++c) {
    cv::Mat strip(cell, col_h + 4, CV_8UC3, cv::Scalar(255, 255, 255));
    cv::putText(strip, spec.cols[c], {2, cell - 5}, font, fs, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    cv::Mat up;
    cv::rotate(strip, up, cv::ROTATE_90_COUNTERCLOCKWISE);
    up.copyTo(img(cv::Rect(left + c * cell, top - up.rows - 2, up.cols, up.rows)));
  }
  for (int r = 0; r < nr; ++r) {
    const int y = top + r * cell;
    cv::putText(img, spec.rows[r], {left - 6 - textWidth(spec.rows[r], fs), y + cell - 5}, font, fs,
                cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    int total = 0;
    for (int c = 0; c < nc; ++c) total += spec.counts[r][c];
    for (int c = 0; c < nc; ++c) {
      const cv::Rect box(left + c * cell, y, cell, cell);
      const int n = spec.counts[r][c];
      // White (none) to dark blue (the whole row).
      const double f = total > 0 ? static_cast<double>(n) / total : 0.0;
      const cv::Scalar shade(255 - 75 * f, 255 - 200 * f, 255 - 225 * f);
      cv::rectangle(img, box, shade, cv::FILLED);
      cv::rectangle(img, box, cv::Scalar(225, 225, 225), 1);
      if (n > 0) {
        const std::string t = std::to_string(n);
        cv::putText(img, t, {box.x + (cell - textWidth(t, fs)) / 2, box.y + cell - 5}, font, fs,
                    f > 0.5 ? cv::Scalar(255, 255, 255) : cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
      }
    }
    if (r < static_cast<int>(spec.row_notes.size()))
      cv::putText(img, spec.row_notes[r], {left + nc * cell + 8, y + cell - 5}, font, fs,
                  cv::Scalar(60, 60, 60), 1, cv::LINE_AA);
  }
  // The right answers' outlines last, so no neighbouring cell's border covers them.
  for (int r = 0; r < nr; ++r)
    for (int c = 0; c < nc; ++c)
      if (spec.cols[c] == spec.rows[r])
        cv::rectangle(img, cv::Rect(left + c * cell, top + r * cell, cell, cell),
                      cv::Scalar(40, 160, 40), 2);
  cv::putText(img, "rows: true class; columns: answer (shaded by share of the row)",
              {10, img.rows - 10}, font, fs, cv::Scalar(90, 90, 90), 1, cv::LINE_AA);
  return img;
}

}  // namespace sketchnav::run
