#include "spidar/render/plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/imgproc.hpp>

namespace spidar::render {
namespace {

/// A "nice" tick step for a span: 1, 2 or 5 × 10^k, about `count` ticks.
double tick_step(double span, int count) {
  const double raw = span / std::max(1, count);
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * p >= raw) return m * p;
  }
  return 10 * p;
}

std::string tick_label(double v, double step) {
  char buf[32];
  const int decimals = step >= 1 ? 0 : static_cast<int>(std::ceil(-std::log10(step)));
  std::snprintf(buf, sizeof buf, "%.*f", std::min(decimals, 6), std::abs(v) < 1e-12 ? 0.0 : v);
  return buf;
}

cv::Scalar colour(const std::array<std::uint8_t, 3>& c) { return cv::Scalar(c[0], c[1], c[2]); }

}  // namespace

std::array<std::uint8_t, 3> plot_colour(int i) {
  static constexpr std::array<std::array<std::uint8_t, 3>, 8> k{{{178, 114, 0},
                                                                  {0, 159, 230},
                                                                  {115, 158, 0},
                                                                  {167, 121, 204},
                                                                  {66, 228, 240},
                                                                  {0, 94, 213},
                                                                  {233, 180, 86},
                                                                  {60, 60, 60}}};
  return k[static_cast<std::size_t>(((i % 8) + 8) % 8)];
}

Result<cv::Mat> plot_lines(const PlotSpec& spec, std::span<const PlotSeries> series) {
  if (spec.width < 200 || spec.height < 120)
    return Error{"plot '" + spec.title + "': size must be at least 200x120 px"};
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const auto& s : series) {
    if (s.x.size() != s.y.size())
      return Error{"plot '" + spec.title + "': series '" + s.label + "' has " +
                   std::to_string(s.x.size()) + " x and " + std::to_string(s.y.size()) + " y values"};
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      x0 = std::min(x0, s.x[i]);
      x1 = std::max(x1, s.x[i]);
      y0 = std::min(y0, s.y[i]);
      y1 = std::max(y1, s.y[i]);
    }
  }
  for (const auto& r : spec.references) {
    y0 = std::min(y0, r.y);
    y1 = std::max(y1, r.y);
  }
  if (!std::isfinite(x0)) x0 = 0, x1 = 1;
  if (!std::isfinite(y0)) y0 = 0, y1 = 1;
  if (spec.y_min) y0 = *spec.y_min;
  if (spec.y_max) y1 = *spec.y_max;
  if (x1 <= x0) x1 = x0 + 1;
  if (y1 <= y0) y1 = y0 + 1;
  if (!spec.y_min && !spec.y_max) {  // a little headroom
    const double pad = 0.05 * (y1 - y0);
    y0 -= pad;
    y1 += pad;
  }

  cv::Mat img(spec.height, spec.width, CV_8UC3, cv::Scalar(255, 255, 255));
  const int left = 70, right = 170, top = 30, bottom = 45;
  const cv::Rect area(left, top, spec.width - left - right, spec.height - top - bottom);
  auto px = [&](double x, double y) {
    return cv::Point2d(area.x + (x - x0) / (x1 - x0) * area.width,
                       area.y + area.height - (y - y0) / (y1 - y0) * area.height);
  };
  const auto font = cv::FONT_HERSHEY_SIMPLEX;
  const cv::Scalar grid(225, 225, 225), ink(40, 40, 40);
  const double xs = tick_step(x1 - x0, 8), ys = tick_step(y1 - y0, 5);
  for (double x = std::ceil(x0 / xs) * xs; x <= x1 + 1e-9; x += xs) {
    const cv::Point2d a = px(x, y0);
    cv::line(img, cv::Point(static_cast<int>(a.x), area.y), cv::Point(static_cast<int>(a.x), area.br().y), grid);
    cv::putText(img, tick_label(x, xs), cv::Point(static_cast<int>(a.x) - 10, area.br().y + 16), font, 0.4, ink, 1, cv::LINE_AA);
  }
  for (double y = std::ceil(y0 / ys) * ys; y <= y1 + 1e-9; y += ys) {
    const cv::Point2d a = px(x0, y);
    cv::line(img, cv::Point(area.x, static_cast<int>(a.y)), cv::Point(area.br().x, static_cast<int>(a.y)), grid);
    cv::putText(img, tick_label(y, ys), cv::Point(4, static_cast<int>(a.y) + 4), font, 0.4, ink, 1, cv::LINE_AA);
  }
  cv::rectangle(img, area, ink);
  for (const auto& r : spec.references) {
    const int y = static_cast<int>(px(x0, r.y).y);
    for (int x = area.x; x < area.br().x; x += 12)
      cv::line(img, cv::Point(x, y), cv::Point(std::min(x + 6, area.br().x), y), colour(r.bgr), 1, cv::LINE_AA);
  }
  cv::Mat clip = img(area);
  for (const auto& s : series) {
    for (std::size_t i = 1; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i - 1] + s.y[i - 1] + s.x[i] + s.y[i])) continue;
      const cv::Point2d a = px(s.x[i - 1], s.y[i - 1]) - cv::Point2d(area.x, area.y);
      const cv::Point2d b = px(s.x[i], s.y[i]) - cv::Point2d(area.x, area.y);
      cv::line(clip, cv::Point(cvRound(a.x), cvRound(a.y)), cv::Point(cvRound(b.x), cvRound(b.y)),
               colour(s.bgr), 1, cv::LINE_AA);
    }
  }
  cv::putText(img, spec.title, cv::Point(left, 20), font, 0.55, ink, 1, cv::LINE_AA);
  cv::putText(img, spec.x_label, cv::Point(area.x + area.width / 2 - 20, spec.height - 8), font, 0.45, ink, 1, cv::LINE_AA);
  cv::putText(img, spec.y_label, cv::Point(4, 20), font, 0.4, ink, 1, cv::LINE_AA);
  int ly = top + 12;
  const int lx = area.br().x + 10;
  for (const auto& s : series) {
    cv::line(img, cv::Point(lx, ly - 4), cv::Point(lx + 20, ly - 4), colour(s.bgr), 2, cv::LINE_AA);
    cv::putText(img, s.label, cv::Point(lx + 26, ly), font, 0.4, ink, 1, cv::LINE_AA);
    ly += 16;
  }
  for (const auto& r : spec.references) {
    cv::line(img, cv::Point(lx, ly - 4), cv::Point(lx + 20, ly - 4), colour(r.bgr), 1, cv::LINE_AA);
    cv::putText(img, r.label, cv::Point(lx + 26, ly), font, 0.4, ink, 1, cv::LINE_AA);
    ly += 16;
  }
  return img;
}

}  // namespace spidar::render
