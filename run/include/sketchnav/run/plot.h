#pragma once
// A small line-plot writer on OpenCV (axes, ticks, labels, legend) for `tune` and reports:
// enough for a handful of series, no plotting library needed.
#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace sketchnav::run {

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

/// A confusion matrix: rows are the true classes, columns the answers; counts[r][c].
struct ConfusionSpec {
  std::string title;
  std::vector<std::string> rows, cols;
  std::vector<std::vector<int>> counts;  // rows.size() x cols.size()
  std::vector<std::string> row_notes;    // printed right of each row (e.g. its top-1); optional
};

/// Draws the matrix as a heat map: each cell shaded by its share of the row (so classes with
/// few images read the same as classes with many), its count printed, the cells whose column
/// names the row's class outlined (the right answers), column labels written vertically.
cv::Mat drawConfusionMatrix(const ConfusionSpec& spec);

/// A distinct colour for series i.
cv::Scalar plotColor(int i);

}  // namespace sketchnav::run
