// The compositor against a straightforward reference written here: each step of its doc comment
// as a separate full-image pass (threshold, distance transform, per-pixel carry, cv::blur of the
// float mask, cv::multiply, per-pixel blend). The compositor fuses these passes into few loops
// over the matte's bounding box; its composite and alpha must be identical, bit for bit, over
// hand-made scenes with soft mattes, depth ramps, hands at the image border, odd sizes, and every
// combination of the parameters that change a step.
#include <gtest/gtest.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "spidar/render/compositor.hpp"

namespace spidar::render {
namespace {

constexpr float kNoDepth = std::numeric_limits<float>::infinity();

struct LayeredScene {
  RenderTargets virt;
  cv::Mat real_bgr, alpha;
};

struct Composite {
  cv::Mat out, alpha;
};

/// A scene of `size`: an object with a depth ramp, a virtual hand of a few blobs at depths
/// around the object's, and a real hand (the blobs shifted, with a soft-edged matte whose values
/// are multiples of 1/255 as the chroma key's). `seed` varies the layout.
LayeredScene make_layered_scene(cv::Size size, int seed, bool at_border) {
  cv::RNG rng(static_cast<std::uint64_t>(seed) + 1);
  LayeredScene s;
  s.virt.colour.create(size, CV_8UC3);
  rng.fill(s.virt.colour, cv::RNG::UNIFORM, 0, 256);
  s.virt.depth = cv::Mat(size, CV_32FC1, kNoDepth);
  s.virt.hand_depth = cv::Mat(size, CV_32FC1, kNoDepth);
  s.virt.hand_id = cv::Mat(size, CV_8UC1, cv::Scalar(0));
  // The object: a rectangle whose depth rises to the right (0.45 .. 0.55 m).
  const cv::Rect object(size.width / 5, size.height / 4, size.width / 2, size.height / 2);
  for (int y = object.y; y < object.y + object.height; ++y)
    for (int x = object.x; x < object.x + object.width; ++x)
      s.virt.depth.at<float>(y, x) = 0.45f + 0.1f * static_cast<float>(x - object.x) / static_cast<float>(object.width);
  // The virtual hand: ellipses (fingers, palm) at 0.42 .. 0.58 m, a tilt across each.
  cv::Mat hand_mask(size, CV_8UC1, cv::Scalar(0));
  const int blobs = 3 + seed % 3;
  for (int b = 0; b < blobs; ++b) {
    cv::Point c(rng.uniform(0, size.width), rng.uniform(0, size.height));
    if (at_border && b == 0) c = cv::Point(size.width - 3, 2);  // runs off the corner
    const cv::Size axes(rng.uniform(4, size.width / 5), rng.uniform(4, size.height / 4));
    cv::Mat blob(size, CV_8UC1, cv::Scalar(0));
    cv::ellipse(blob, c, axes, rng.uniform(0.0, 180.0), 0, 360, cv::Scalar(255), cv::FILLED);
    const float d0 = static_cast<float>(rng.uniform(0.42, 0.58));
    for (int y = 0; y < size.height; ++y)
      for (int x = 0; x < size.width; ++x) {
        if (!blob.at<std::uint8_t>(y, x)) continue;
        float& hd = s.virt.hand_depth.at<float>(y, x);
        hd = std::min(hd, d0 + 0.0005f * static_cast<float>(y - c.y));
      }
    hand_mask |= blob;
  }
  s.virt.hand_id.setTo(encode_hand_id(seed % 2, 1), hand_mask);
  // The real hand: the virtual one shifted, plus a blob no virtual pixel is near; soft edges.
  cv::Mat real_mask;
  const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, rng.uniform(-6, 7), 0, 1, rng.uniform(-6, 7));
  cv::warpAffine(hand_mask, real_mask, shift, size, cv::INTER_NEAREST);
  cv::circle(real_mask, cv::Point(rng.uniform(0, size.width), size.height - 4), 5, cv::Scalar(255),
             cv::FILLED);
  cv::Mat soft;
  cv::GaussianBlur(real_mask, soft, cv::Size(5, 5), 1.2);
  soft.convertTo(s.alpha, CV_32F, 1.0 / 255.0);
  s.real_bgr.create(size, CV_8UC3);
  rng.fill(s.real_bgr, cv::RNG::UNIFORM, 0, 256);
  return s;
}

/// The depth mode, pass by pass, as the compositor's doc comment states it.
Composite reference_depth(const LayeredScene& s, const CompositorParams& p) {
  const RenderTargets& v = s.virt;
  Composite c{v.colour.clone(), cv::Mat(v.colour.size(), CV_32FC1, 0.f)};
  cv::Rect roi = cv::boundingRect(s.alpha > 0.f);
  if (roi.area() == 0) return c;
  const int r = p.edge_blur_px;
  roi = cv::Rect(roi.x - r, roi.y - r, roi.width + 2 * r, roi.height + 2 * r) &
        cv::Rect(0, 0, v.colour.cols, v.colour.rows);
  // The nearest virtual-hand pixel (or 2×2 block) of every pixel within max_carry_px.
  vision::SilhouetteDistance d;
  vision::SilhouetteDistanceOptions o;
  o.max_distance_px = p.max_carry_px;
  o.downsample = p.carry_downsample;
  EXPECT_TRUE(vision::silhouette_distance(v.hand_depth < FLT_MAX, &d, o).ok());
  const int sc = d.scale;
  cv::Mat front(roi.size(), CV_32FC1);
  for (int y = roi.y; y < roi.y + roi.height; ++y) {
    for (int x = roi.x; x < roi.x + roi.width; ++x) {
      float f = p.show_unmatched ? 1.f : 0.f;  // no hand depth reaches this pixel
      if (!d.empty && d.roi.contains(cv::Point(x, y))) {
        const int lx = (x - d.roi.x) / sc, ly = (y - d.roi.y) / sc;
        const int l = d.labels.at<int>(ly, lx);
        const bool reached = d.distance.at<float>(ly, lx) <= static_cast<float>(p.max_carry_px) / static_cast<float>(sc);
        if (reached && l > 0 && l < static_cast<int>(d.label_pixel.size()) && d.label_pixel[static_cast<std::size_t>(l)].x >= 0) {
          // The front-most hand depth of the nearest cell.
          const cv::Point q = d.label_pixel[static_cast<std::size_t>(l)];
          float carried = FLT_MAX;
          for (int yy = q.y; yy < std::min(q.y + sc, v.colour.rows); ++yy)
            for (int xx = q.x; xx < std::min(q.x + sc, v.colour.cols); ++xx)
              carried = std::min(carried, v.hand_depth.at<float>(yy, xx));
          f = carried < v.depth.at<float>(y, x) + static_cast<float>(p.depth_margin_m) ? 1.f : 0.f;
        }
      }
      front.at<float>(y - roi.y, x - roi.x) = f;
    }
  }
  if (r > 0) cv::blur(front, front, cv::Size(2 * r + 1, 2 * r + 1), cv::Point(-1, -1), cv::BORDER_REPLICATE);
  cv::Mat a = c.alpha(roi);
  cv::multiply(front, s.alpha(roi), a);
  for (int y = roi.y; y < roi.y + roi.height; ++y) {
    for (int x = roi.x; x < roi.x + roi.width; ++x) {
      const float w = c.alpha.at<float>(y, x);
      if (w <= 0.f) continue;
      for (int k = 0; k < 3; ++k) {
        std::uint8_t& o8 = c.out.at<cv::Vec3b>(y, x)[k];
        const float value = w * s.real_bgr.at<cv::Vec3b>(y, x)[k] + (1.f - w) * o8;
        o8 = static_cast<std::uint8_t>(std::clamp(value + 0.5f, 0.f, 255.f));
      }
    }
  }
  return c;
}

/// The paper mode: the real image where the virtual hand is front-most.
Composite reference_paper(const LayeredScene& s) {
  const RenderTargets& v = s.virt;
  const cv::Mat front = v.hand_depth < v.depth;
  Composite c{v.colour.clone(), cv::Mat()};
  s.real_bgr.copyTo(c.out, front);
  front.convertTo(c.alpha, CV_32F, 1.0 / 255.0);
  return c;
}

/// Number of pixels where two images differ (any channel).
int differing(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return -1;
  cv::Mat diff;
  cv::compare(a, b, diff, cv::CMP_NE);
  return cv::countNonZero(diff.reshape(1));
}

TEST(CompositorReference, DepthModeIsTheReferenceBitForBit) {
  // One compositor for every case, its buffers reused across sizes and settings; the caller's
  // output buffers hold garbage from the previous case.
  Compositor compositor;
  cv::Mat out, alpha;
  int cases = 0;
  for (const cv::Size size : {cv::Size(160, 120), cv::Size(131, 97)}) {
    for (int seed = 0; seed < 3; ++seed) {
      const LayeredScene s = make_layered_scene(size, seed, seed == 1);
      for (int blur : {0, 1, 3, 16}) {
        for (int downsample : {1, 2}) {
          for (int carry : {1, 7, 48}) {
            for (bool unmatched : {true, false}) {
              for (double margin : {0.0, 0.02}) {
                CompositorParams p;
                p.mode = CompositeMode::kDepth;
                p.edge_blur_px = blur;
                p.carry_downsample = downsample;
                p.max_carry_px = carry;
                p.show_unmatched = unmatched;
                p.depth_margin_m = margin;
                compositor.set_params(p);
                const auto st = compositor.compose({&s.virt, s.real_bgr, s.alpha}, &out, &alpha);
                ASSERT_TRUE(st.ok()) << st.error().message;
                const Composite want = reference_depth(s, p);
                const std::string what = std::to_string(size.width) + "x" + std::to_string(size.height) +
                                         " seed " + std::to_string(seed) + " blur " + std::to_string(blur) +
                                         " downsample " + std::to_string(downsample) + " carry " +
                                         std::to_string(carry) + (unmatched ? " shown" : " hidden") +
                                         " margin " + std::to_string(margin);
                ASSERT_EQ(differing(out, want.out), 0) << what;
                ASSERT_EQ(differing(alpha, want.alpha), 0) << what;
                ASSERT_EQ(compositor.last_alpha().data, alpha.data) << what;
                ++cases;
              }
            }
          }
        }
      }
    }
  }
  EXPECT_EQ(cases, 2 * 3 * 4 * 2 * 3 * 2 * 2);
}

TEST(CompositorReference, DepthModeScenesShowBothOutcomes) {
  // The scenes above are not trivial: the real hand is partly in front of the object, partly
  // behind it, with soft edges, so a wrong carry or blur would change pixels.
  const LayeredScene s = make_layered_scene(cv::Size(160, 120), 0, false);
  const Composite c = reference_depth(s, CompositorParams{});
  const cv::Mat in_matte = s.alpha > 0.f;
  EXPECT_GT(cv::countNonZero(c.alpha >= 1.f), 100);
  EXPECT_GT(cv::countNonZero((c.alpha > 0.f) & (c.alpha < 1.f)), 50);
  EXPECT_GT(cv::countNonZero((c.alpha == 0.f) & in_matte), 50);
}

TEST(CompositorReference, PaperModeIsTheReferenceBitForBit) {
  Compositor compositor({CompositeMode::kPaper});
  cv::Mat out, alpha;
  for (const cv::Size size : {cv::Size(160, 120), cv::Size(131, 97)}) {
    for (int seed = 0; seed < 3; ++seed) {
      const LayeredScene s = make_layered_scene(size, seed, seed == 1);
      ASSERT_TRUE(compositor.compose({&s.virt, s.real_bgr, s.alpha}, &out, &alpha).ok());
      const Composite want = reference_paper(s);
      ASSERT_GT(cv::countNonZero(want.alpha), 100);
      EXPECT_EQ(differing(out, want.out), 0) << seed;
      EXPECT_EQ(differing(alpha, want.alpha), 0) << seed;
      // The same within the hands' box, as the renderer reports it (RenderTargets::hand_box);
      // the caller's buffers hold the previous composite.
      LayeredScene boxed = s;
      boxed.virt.hand_box = cv::boundingRect(s.virt.hand_depth < std::numeric_limits<float>::infinity());
      ASSERT_LT(boxed.virt.hand_box->area(), size.area());  // the box leaves pixels out
      ASSERT_TRUE(compositor.compose({&boxed.virt, s.real_bgr, s.alpha}, &out, &alpha).ok());
      EXPECT_EQ(differing(out, want.out), 0) << seed << " (hand box)";
      EXPECT_EQ(differing(alpha, want.alpha), 0) << seed << " (hand box)";
    }
  }
}

TEST(CompositorReference, OwnAlphaBufferIsNotTheOneLentBefore) {
  // After a composite into the caller's alpha, one without it must not write into that buffer.
  const LayeredScene s = make_layered_scene(cv::Size(160, 120), 2, false);
  Compositor compositor;
  cv::Mat out, lent;
  ASSERT_TRUE(compositor.compose({&s.virt, s.real_bgr, s.alpha}, &out, &lent).ok());
  const cv::Mat kept = lent.clone();
  LayeredScene other = s;
  other.alpha = cv::Mat(s.alpha.size(), CV_32FC1, 0.f);
  ASSERT_TRUE(compositor.compose({&other.virt, other.real_bgr, other.alpha}, &out).ok());
  EXPECT_EQ(differing(lent, kept), 0);
  EXPECT_NE(compositor.last_alpha().data, lent.data);
  EXPECT_EQ(cv::countNonZero(compositor.last_alpha()), 0);
}

}  // namespace
}  // namespace spidar::render
