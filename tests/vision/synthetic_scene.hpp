#pragma once
// Synthetic camera frames for the vision tests: skin-coloured hands (forearm, palm, fingers)
// over a blue screen with uneven lighting, shadows, soft (supersampled) edges and sensor noise,
// red wrist bracelets, and the ground truth (coverage matte, wrist positions).
#include <array>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <random>
#include <vector>

#include "spidar/core/types.hpp"
#include "spidar/core/units.hpp"

namespace spidar::vision::test {

struct DrawnHand {
  cv::Point2d wrist;        // band centre [px]
  double angle = -units::kPi / 2;  // direction wrist → fingers [rad] in the image (−π/2 = up)
  double length = 150;      // wrist to fingertips [px]
  bool bracelet = true;
  double hidden_fraction = 0;  // part of the band (from its end_b side) covered by skin
  bool finger_across = false;  // a finger of the other hand lies across the band's middle
};

struct SceneOptions {
  cv::Size size{640, 480};
  double noise_sigma = 3.0;   // per channel, 0..255
  double light_min = 0.45;    // lighting gain ramps from this to 1 across the image
  double shadow = 0.5;        // gain inside the hands' shadows on the screen (1 = none)
  double spill = 0.0;         // blue added to the hands' edge pixels (0..255)
  unsigned seed = 1;
};

struct Scene {
  cv::Mat bgr;          // CV_8UC3
  cv::Mat coverage;     // CV_32FC1, hand coverage 0..1 (ground-truth matte)
  std::array<std::optional<Vec2>, 2> wrist;  // true band centres (hands in input order)
  std::vector<std::array<Vec2, 2>> band_ends;
};

inline constexpr int kSuper = 4;

// Output pixel coordinates (centre convention) → supersampled drawing coordinates with 4
// fractional bits: output pixel i spans supersampled pixels kSuper·i .. kSuper·i + kSuper − 1,
// whose centre is kSuper·i + (kSuper − 1)/2.
inline cv::Point sp(double x, double y) {
  const double o = (kSuper - 1) / 2.0;
  return {static_cast<int>(std::lround((x * kSuper + o) * 16)), static_cast<int>(std::lround((y * kSuper + o) * 16))};
}

// Fills a rotated rectangle given in output-pixel units into a supersampled mask/image.
inline void fill_rotated(cv::Mat& img, cv::Point2d c, cv::Point2d u, double half_len,
                         double half_thick, const cv::Scalar& colour) {
  const cv::Point2d v(-u.y, u.x);
  std::vector<cv::Point> pts;
  for (auto [a, b] : {std::pair{-1, -1}, std::pair{1, -1}, std::pair{1, 1}, std::pair{-1, 1}}) {
    const cv::Point2d q = c + a * half_len * u + b * half_thick * v;
    pts.push_back(sp(q.x, q.y));
  }
  cv::fillConvexPoly(img, pts, colour, cv::LINE_8, 4);
}

inline void draw_capsule(cv::Mat& img, cv::Point2d a, cv::Point2d b, double radius,
                         const cv::Scalar& colour) {
  cv::line(img, sp(a.x, a.y), sp(b.x, b.y), colour,
           static_cast<int>(std::lround(2 * radius * kSuper)), cv::LINE_8, 4);
}

// Draws one hand's skin parts into a supersampled 1-channel mask (255 = skin).
inline void draw_hand_mask(cv::Mat& mask, const DrawnHand& h) {
  const cv::Point2d d(std::cos(h.angle), std::sin(h.angle));
  const cv::Point2d n(-d.y, d.x);
  const double L = h.length;
  const double arm_half = 0.2 * L;
  // Forearm: from the wrist far back (out of the image).
  fill_rotated(mask, h.wrist - 2.0 * L * d, d, 2.0 * L, arm_half, cv::Scalar(255));
  // Palm.
  const cv::Point2d palm = h.wrist + 0.32 * L * d;
  cv::ellipse(mask, sp(palm.x, palm.y), cv::Size(static_cast<int>(0.3 * L * kSuper * 16), static_cast<int>(0.27 * L * kSuper * 16)),
              h.angle * 180 / units::kPi, 0, 360, cv::Scalar(255), -1, cv::LINE_8, 4);
  // Four fingers and a thumb.
  const double spread[4] = {-0.17, -0.06, 0.05, 0.16};
  const double flen[4] = {0.42, 0.47, 0.44, 0.34};
  for (int f = 0; f < 4; ++f) {
    const cv::Point2d base = h.wrist + 0.58 * L * d + spread[f] * L * n;
    const double fan = (f - 1.5) * 0.08;
    const cv::Point2d dir(std::cos(h.angle + fan), std::sin(h.angle + fan));
    draw_capsule(mask, base, base + flen[f] * L * dir, 0.045 * L, cv::Scalar(255));
  }
  const cv::Point2d tb = h.wrist + 0.2 * L * d - 0.2 * L * n;
  const double ta = h.angle - 0.9;
  draw_capsule(mask, tb, tb + 0.32 * L * cv::Point2d(std::cos(ta), std::sin(ta)), 0.055 * L,
               cv::Scalar(255));
}

inline Scene draw_scene(const std::vector<DrawnHand>& hands, const SceneOptions& o = {}) {
  const cv::Size big(o.size.width * kSuper, o.size.height * kSuper);
  cv::Mat skin(big, CV_8UC1, cv::Scalar(0)), red(big, CV_8UC1, cv::Scalar(0));
  Scene s;
  for (std::size_t i = 0; i < hands.size(); ++i) {
    const auto& h = hands[i];
    draw_hand_mask(skin, h);
    if (!h.bracelet) continue;
    const cv::Point2d d(std::cos(h.angle), std::sin(h.angle));
    const cv::Point2d u(-d.y, d.x);  // band's long axis, across the wrist
    const double half_len = 0.22 * h.length, half_thick = 0.07 * h.length;
    fill_rotated(red, h.wrist, u, half_len, half_thick, cv::Scalar(255));
    if (i < 2) s.wrist[i] = Vec2(h.wrist.x, h.wrist.y);
    s.band_ends.push_back({Vec2(h.wrist.x - half_len * u.x, h.wrist.y - half_len * u.y),
                           Vec2(h.wrist.x + half_len * u.x, h.wrist.y + half_len * u.y)});
  }
  // Occluders (skin over the band), drawn after the bands.
  for (const auto& h : hands) {
    if (!h.bracelet) continue;
    const cv::Point2d d(std::cos(h.angle), std::sin(h.angle));
    const cv::Point2d u(-d.y, d.x);
    const double half_len = 0.22 * h.length;
    if (h.hidden_fraction > 0) {
      const double cover = h.hidden_fraction * 2 * half_len;
      const cv::Point2d c = h.wrist + (half_len - 0.5 * cover + 2.0) * u;
      cv::Mat occ(big, CV_8UC1, cv::Scalar(0));
      fill_rotated(occ, c, u, 0.5 * cover + 2.0, 0.2 * h.length, cv::Scalar(255));
      skin.setTo(255, occ);
      red.setTo(0, occ);
    }
    if (h.finger_across) {
      cv::Mat occ(big, CV_8UC1, cv::Scalar(0));
      draw_capsule(occ, h.wrist - 0.3 * h.length * d, h.wrist + 0.3 * h.length * d,
                   0.04 * h.length, cv::Scalar(255));
      skin.setTo(255, occ);
      red.setTo(0, occ);
    }
  }
  cv::Mat hand_big;
  cv::bitwise_or(skin, red, hand_big);
  // Colour at supersampled resolution (float, linear): screen, skin, band.
  cv::Mat colour(big, CV_32FC3, cv::Scalar(200, 80, 30));  // blue screen (BGR)
  // Shadow of the hands on the screen: the hand mask shifted down-right and blurred.
  cv::Mat shadow_mask;
  const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 14 * kSuper, 0, 1, 10 * kSuper);
  cv::warpAffine(hand_big, shadow_mask, shift, big);
  cv::resize(shadow_mask, shadow_mask, o.size, 0, 0, cv::INTER_AREA);
  cv::GaussianBlur(shadow_mask, shadow_mask, cv::Size(0, 0), 4.0);
  cv::resize(shadow_mask, shadow_mask, big, 0, 0, cv::INTER_LINEAR);
  colour.setTo(cv::Scalar(130, 160, 215), skin);  // skin (R 215, G 160, B 130)
  colour.setTo(cv::Scalar(40, 30, 200), red);     // red band
  cv::Mat small;
  cv::resize(colour, small, o.size, 0, 0, cv::INTER_AREA);
  cv::Mat cov;
  cv::resize(hand_big, cov, o.size, 0, 0, cv::INTER_AREA);
  cov.convertTo(s.coverage, CV_32F, 1.0 / 255.0);
  cv::Mat shadow_small;
  cv::resize(shadow_mask, shadow_small, o.size, 0, 0, cv::INTER_AREA);
  // Lighting: a diagonal ramp, darker shadows on the screen only, blue spill on hand edges.
  std::mt19937 rng(o.seed);
  std::normal_distribution<float> noise(0.0f, static_cast<float>(o.noise_sigma));
  s.bgr.create(o.size, CV_8UC3);
  for (int y = 0; y < o.size.height; ++y) {
    for (int x = 0; x < o.size.width; ++x) {
      const double ramp = (0.6 * x / o.size.width + 0.4 * y / o.size.height);
      const double light = o.light_min + (1.0 - o.light_min) * ramp;
      const float c = s.coverage.at<float>(y, x);
      const double sh = 1.0 - (1.0 - o.shadow) * (shadow_small.at<std::uint8_t>(y, x) / 255.0) * (1.0 - c);
      cv::Vec3f v = small.at<cv::Vec3f>(y, x) * static_cast<float>(light * sh);
      if (c > 0.f && c < 1.f) v[0] += static_cast<float>(o.spill);
      for (int k = 0; k < 3; ++k) {
        s.bgr.at<cv::Vec3b>(y, x)[k] = cv::saturate_cast<std::uint8_t>(v[k] + noise(rng));
      }
    }
  }
  return s;
}

}  // namespace spidar::vision::test
