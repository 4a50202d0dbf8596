#pragma once
/// Line plots as images (for the demo's report): one panel with axes, ticks, a legend and
/// optional horizontal reference lines (targets). Drawn with OpenCV, anti-aliased.
#include <array>
#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "spidar/core/result.hpp"

namespace spidar::render {

struct PlotSeries {
  std::string label;
  std::vector<double> x, y;               ///< same length; non-finite points break the line
  std::array<std::uint8_t, 3> bgr{200, 80, 30};
};

struct PlotReference {
  std::string label;
  double y = 0;
  std::array<std::uint8_t, 3> bgr{60, 60, 200};
};

struct PlotSpec {
  std::string title, x_label, y_label;
  int width = 960, height = 360;  ///< [px]
  std::optional<double> y_min, y_max;  ///< default: the data's range (and the references')
  std::vector<PlotReference> references;
};

/// Draws the series into a new CV_8UC3 image. Error if a series' x and y differ in length or
/// the size is below 200×120 px.
Result<cv::Mat> plot_lines(const PlotSpec& spec, std::span<const PlotSeries> series);

/// A standard colour per series index (distinguishable, colour-blind friendly order).
std::array<std::uint8_t, 3> plot_colour(int index);

}  // namespace spidar::render
