#pragma once
// A small line-plot writer on OpenCV (axes, ticks, labels, legend) for `tune` and reports:
// enough for a handful of series, no plotting library needed.
#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace sketchnav::app {

struct PlotSeries {
  std::string label;
  std::vector<double> x, y;       // NaN y values are skipped
  cv::Scalar color{200, 60, 20};  // BGR
};

struct PlotSpec {
  std::string title, x_label, y_label;
  int width = 640, height = 400;    // [px]
  double y_min = NAN, y_max = NAN;  // NaN: from the data
  double marker_x = NAN;  // a vertical dashed line (e.g. the recommended value); NaN = none
};

/// Draws the series as lines with dots; returns the image.
cv::Mat drawLinePlot(const PlotSpec& spec, const std::vector<PlotSeries>& series);

/// A distinct colour for series i.
cv::Scalar plotColor(int i);

}  // namespace sketchnav::app
