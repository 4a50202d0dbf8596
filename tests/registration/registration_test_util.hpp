#pragma once
// Shared set-up of the registration tests: hands over the frame centre for the rig camera,
// perturbations, a GL-free capsule silhouette, and synthetic frames from the simulated camera.
#include <gtest/gtest.h>

#include <array>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>

#include "spidar/hand/hand_config.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/hand/kinematics.hpp"
#include "spidar/hand/render_geometry.hpp"
#include "spidar/hand/rotation_vector.hpp"
#include "spidar/registration/successive_adjustment.hpp"
#include "spidar/render/context.hpp"
#include "spidar/sim/synthetic_camera.hpp"
#include "spidar/vision/bracelet.hpp"
#include "spidar/vision/camera.hpp"
#include "spidar/vision/chroma_key.hpp"
#include "spidar/registration/coverage.hpp"
#include "spidar/vision/silhouette.hpp"

namespace spidar::registration::test {

/// Both hands reaching over the frame centre, fingers partly flexed, seen by the rig camera
/// (index 0 left, 1 right). `variant` changes the finger flexion a little.
inline std::array<hand::HandParams, 2> reaching_hands(int variant = 0) {
  hand::HandParams right;
  right.set_wrist(Vec3(0.11, -0.05, 0.04), Vec3(0.05, -0.1, 1.05));
  right[hand::kThumbCmcFlexion] = 0.3;
  right[hand::kThumbCmcAbduction] = 0.45;
  right[hand::kThumbIp] = 0.35;
  const double flex = 0.45 + 0.1 * variant;
  right[hand::kIndexMcpFlexion] = flex;
  right[hand::kMiddleMcpFlexion] = flex + 0.1;
  right[hand::kRingMcpFlexion] = flex + 0.15;
  right[hand::kIndexMcpAbduction] = 0.08;
  right[hand::kRingMcpAbduction] = 0.05;
  right[hand::kIndexDip] = 0.4;
  right[hand::kMiddleDip] = 0.5;
  right[hand::kRingDip] = 0.55;
  return {hand::mirror_params(right), right};
}

/// The rig camera without distortion, its resolution and focal length × `scale` (2: a pixel ≈ 0.4
/// mm at the hands): 0.45 m from the world origin, looking down at 50°.
inline vision::Camera pinhole_camera(double scale = 1.0) {
  vision::Camera c = vision::default_rig_camera();
  vision::Intrinsics k = c.intrinsics();
  k.distortion = {};
  k.fx *= scale;
  k.fy *= scale;
  k.cx *= scale;
  k.cy *= scale;
  k.width = static_cast<int>(k.width * scale);
  k.height = static_cast<int>(k.height * scale);
  c.set_intrinsics(k);
  return c;
}

/// The "user" profile of configs/hands.yaml: the ground-truth hands (left, right).
inline std::array<hand::HandModel, 2> truth_models() {
  const auto profiles = hand::load_hand_profiles(SPIDAR_SOURCE_DIR "/configs/hands.yaml");
  const hand::HandProfile* user = profiles.find("user");
  if (!user) throw std::runtime_error("configs/hands.yaml has no profile 'user'");
  return {user->model(hand::Side::kLeft), user->model(hand::Side::kRight)};
}

/// The registration's model hands (default sizes).
inline std::array<hand::HandModel, 2> model_hands() {
  return {hand::default_hand_model(hand::Side::kLeft), hand::default_hand_model(hand::Side::kRight)};
}

/// Wrist ±wrist_m per axis, rotation by a random axis times up to rotation_rad, joints ±joint_rad;
/// clamped into the limits.
inline hand::HandParams perturb(const hand::HandParams& q, const hand::HandModel& model,
                                std::mt19937& rng, double wrist_m = 0.015,
                                double rotation_rad = 0.15, double joint_rad = 0.2) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  hand::HandParams p = q;
  for (int i = 0; i < 3; ++i) p[i] += wrist_m * u(rng);
  Vec3 axis(u(rng), u(rng), u(rng));
  axis.normalize();
  const Mat3 R = Eigen::AngleAxisd(rotation_rad * u(rng), axis).toRotationMatrix() *
                 hand::rotation_from_vector(q.r_W_hand());
  const Eigen::AngleAxisd aa(R);
  p.set_wrist(p.p_W_wrist(), aa.angle() * aa.axis());
  for (int i = hand::kThumbCmcFlexion; i < hand::kParamCount; ++i) p[i] += joint_rad * u(rng);
  return hand::clamp_to_limits(p, model.limits);
}

/// A silhouette drawn from a model's own capsules and palm box (no GL): CV_8UC1, 255 = hand.
/// `box_palm` false: the palm as the slab palm_breadth.hpp's chords assume (the box's breadth
/// with its edges rounded by its half thickness) instead of the box's corners. `exact_digits`: the
/// digits drawn at sub-pixel precision (a polygon and discs with fractional corners: a pixel is
/// on where its centre is inside), so that a digit is as wide in the mask as its capsule; without
/// it a thick 8-connected line is drawn, about a pixel wider.
inline void draw_capsule_mask(const hand::HandModel& model, const hand::HandParams& q,
                              const vision::Camera& camera, cv::Mat* mask, bool box_palm = true,
                              bool exact_digits = false) {
  if (mask->empty()) *mask = cv::Mat::zeros(camera.height(), camera.width(), CV_8UC1);
  const double f = camera.intrinsics().fx;
  const auto shapes = hand::hand_render_shapes(model, q);
  for (const auto& c : shapes.capsules) {
    const Vec2 a = camera.project(c.p_W_a), b = camera.project(c.p_W_b);
    const double r = c.radius * f / camera.depth(0.5 * (c.p_W_a + c.p_W_b));
    if (exact_digits) {
      constexpr int kShift = 8;
      constexpr double kOne = 1 << kShift;
      auto fixed = [&](const Vec2& p) {
        return cv::Point(static_cast<int>(std::lround(p.x() * kOne)), static_cast<int>(std::lround(p.y() * kOne)));
      };
      const Vec2 d = b - a;
      if (d.norm() > 1e-9) {
        const Vec2 n = r * Vec2(-d.y(), d.x()).normalized();
        const cv::Point quad[4] = {fixed(a + n), fixed(b + n), fixed(b - n), fixed(a - n)};
        cv::fillConvexPoly(*mask, quad, 4, 255, cv::LINE_8, kShift);
      }
      for (const Vec2& e : {a, b})
        cv::circle(*mask, fixed(e), static_cast<int>(std::lround(r * kOne)), 255, cv::FILLED, cv::LINE_8, kShift);
      continue;
    }
    const int thick = std::max(1, static_cast<int>(std::lround(2 * r)));
    cv::line(*mask, cv::Point2d(a.x(), a.y()), cv::Point2d(b.x(), b.y()), 255, thick, cv::LINE_8);
    for (const Vec2& e : {a, b})
      cv::circle(*mask, cv::Point2d(e.x(), e.y()), static_cast<int>(std::lround(r)), 255, cv::FILLED);
  }
  for (const auto& box : shapes.boxes) {
    std::vector<cv::Point> pts;
    const Mat3 R = box.X_WB.R.toRotationMatrix();
    const Vec3& e = box.half_extents;
    Mat3 A = R;  // right-hand H → world (the box's x is mirrored for a left hand)
    if (model.side == hand::Side::kLeft) A.col(0) = -A.col(0);
    for (int level = 0; !box_palm && level <= 10; ++level) {
      const double y = -e.y() + 0.2 * e.y() * level, r = std::min(e.z(), e.x());
      for (int i = 0; i < 32; ++i) {
        const double phi = 2.0 * 3.14159265358979 * (i + 0.5) / 32;
        const double x = (std::cos(phi) >= 0 ? e.x() - r : r - e.x()) + r * std::cos(phi);
        const Vec2 uv = camera.project(box.X_WB.p + A * Vec3(x, y, r * std::sin(phi)));
        pts.emplace_back(static_cast<int>(std::lround(uv.x())), static_cast<int>(std::lround(uv.y())));
      }
    }
    for (int i = 0; box_palm && i < 8; ++i) {
      const Vec3 s((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1);
      const Vec2 uv = camera.project(box.X_WB.p + R * s.cwiseProduct(box.half_extents));
      pts.emplace_back(static_cast<int>(std::lround(uv.x())), static_cast<int>(std::lround(uv.y())));
    }
    std::vector<cv::Point> hull;
    cv::convexHull(pts, hull);
    cv::fillConvexPoly(*mask, hull, 255);
  }
}

/// The silhouette pixels each hand owns with both hands drawn at `poses` (coverage.hpp).
inline std::array<std::vector<OwnedPixel>, 2> owned_pixels(const cv::Mat& silhouette,
                                                     const std::array<hand::HandModel, 2>& models,
                                                     const std::array<hand::HandParams, 2>& poses,
                                                     const vision::Camera& camera,
                                                     const RegistrationParams& params) {
  std::array<ProjectedHand, 2> outline;
  for (int h = 0; h < 2; ++h) {
    const double forearm = bracelet_radius_m(params, models[h].shape.dimensions.width);
    project_hand(models[h], poses[h], camera, forearm, &outline[h]);
  }
  std::array<std::vector<OwnedPixel>, 2> owned;
  coverage_evidence(silhouette, {&outline[0], &outline[1]}, params, &owned);
  return owned;
}

/// Image evidence built from a mask: alpha (mask / 255) and its distance transform.
struct MaskEvidence {
  cv::Mat alpha;
  vision::SilhouetteDistance distance;
  ImageEvidence evidence(const vision::Camera* camera, bool silhouette) const {
    ImageEvidence e;
    e.camera = camera;
    e.alpha = alpha;
    e.distance = silhouette ? &distance : nullptr;
    return e;
  }
};
inline void evidence_from_mask(const cv::Mat& mask, MaskEvidence* out) {
  mask.convertTo(out->alpha, CV_32FC1, 1.0 / 255.0);
  vision::SilhouetteDistanceOptions opt;
  opt.max_distance_px = 40;
  ASSERT_TRUE(vision::silhouette_distance(mask, &out->distance, opt).ok());
}

/// One headless GL context per test process; null (with the reason) when there is none.
struct Gl {
  std::unique_ptr<render::Context> context;
  std::string error;
};
inline Gl& gl() {
  static Gl g = [] {
    Gl s;
    auto r = render::Context::create_headless();
    if (r) s.context = std::move(r).value();
    else s.error = r.error().message;
    return s;
  }();
  return g;
}
#define SPIDAR_SKIP_WITHOUT_GL()                                                    \
  if (!::spidar::registration::test::gl().context)                                \
  GTEST_SKIP() << "no headless OpenGL context (EGL surfaceless): "                 \
               << ::spidar::registration::test::gl().error

/// What the pipeline sees of one synthetic frame: chroma key, bracelets, distance transform.
struct FrameEvidence {
  sim::SyntheticFrame frame;
  vision::ChromaKeyResult key;
  vision::SilhouetteDistance distance;
  std::array<vision::BraceletObservation, 2> bracelets{};
};

/// Films the true hands and runs the vision steps on the image.
inline void film_and_key(sim::SyntheticCamera& camera, const std::array<hand::HandParams, 2>& truth,
                         FrameEvidence* out) {
  ASSERT_TRUE(camera.film({&truth[0], &truth[1]}, &out->frame).ok());
  auto keyer = vision::ChromaKeyer::create(vision::ChromaKeyParams{});
  ASSERT_TRUE(keyer.ok());
  ASSERT_TRUE(keyer->apply(out->frame.bgr, &out->key).ok());
  vision::BraceletWorkspace ws;
  auto b = vision::detect_bracelets(out->frame.bgr, vision::BraceletParams{}, nullptr, &ws);
  ASSERT_TRUE(b.ok()) << b.error().message;
  out->bracelets = *b;
  vision::SilhouetteDistanceOptions opt;
  opt.max_distance_px = 40;
  ASSERT_TRUE(vision::silhouette_distance(out->key.silhouette, &out->distance, opt).ok());
}

/// Fingertips as the strings measure them, exactly: the model's caps at `q`, all valid.
inline HandObservation exact_caps(const hand::HandModel& model, const hand::HandParams& q) {
  const hand::HandPoints pts = hand::forward_kinematics(model, q);
  HandObservation obs;
  for (int f = 0; f < hand::kFingertipCount; ++f) {
    obs.p_W_fingertip[f] = pts.p_W_fingertip[f];
    obs.fingertip_valid[f] = true;
  }
  return obs;
}

/// Fingertips as the strings measure them: the true caps plus Gaussian noise [m] per axis.
inline HandObservation observe(const hand::HandModel& truth_model, const hand::HandParams& truth,
                               const vision::BraceletObservation& bracelet, std::mt19937& rng,
                               double noise_m = 0.0005) {
  std::normal_distribution<double> n(0.0, noise_m);
  const hand::HandPoints p = hand::forward_kinematics(truth_model, truth);
  HandObservation o;
  for (int i = 0; i < hand::kFingertipCount; ++i) {
    o.p_W_fingertip[i] = p.p_W_fingertip[i] + Vec3(n(rng), n(rng), n(rng));
    o.fingertip_valid[i] = true;
  }
  if (bracelet.found) {
    o.wrist_px = bracelet.wrist_px;
    o.wrist_confidence = bracelet.confidence;
  }
  return o;
}

}  // namespace spidar::registration::test
