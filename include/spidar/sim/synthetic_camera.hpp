#pragma once
/// The simulated rig's camera: films the ground-truth ("real") hands against a blue screen, as
/// the lab camera would, so that chroma key, bracelet detection and registration run on images
/// they did not draw themselves.
///
/// The hands are deliberately *not* the registration model's skin: they are the user's own
/// anatomical hands (sim/anatomical_hand.hpp: a palm with its pads, tapered digits with knuckles,
/// webs, fingernails, a wrist and forearm with a red bracelet), skinned to the user's skeleton
/// and posed on the CPU every frame. Skin colour with Lambert shading over a uniformly lit blue
/// screen; then an optical blur (Gaussian PSF), sensor noise (Gaussian, in 8-bit levels) and,
/// optionally, motion blur (the mean of sub-frames between the previous and the current pose).
/// Ground truth comes with every frame: the mask of everything in front of the screen (skin,
/// nails, bracelet, forearm), which hand, and depth.
#include <array>
#include <optional>
#include <cstdint>
#include <memory>
#include <opencv2/core/mat.hpp>

#include "spidar/core/result.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/render/context.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::sim {

struct SyntheticCameraParams {
  std::array<float, 3> screen_rgb{0.15f, 0.35f, 0.78f};   ///< blue screen, as lit
  std::array<float, 3> skin_rgb{0.88f, 0.66f, 0.54f};     ///< skin albedo
  std::array<float, 3> bracelet_rgb{0.85f, 0.07f, 0.07f}; ///< red bracelet albedo
  double bracelet_width_m = 0.018;    ///< along the forearm [m]
  double bracelet_offset_m = 0.012;   ///< bracelet centre, from the wrist toward the elbow [m]
  double forearm_length_m = 0.10;     ///< visible forearm beyond the wrist [m]; 0 = none
  std::array<float, 3> nail_rgb{0.94f, 0.80f, 0.78f};     ///< fingernails' albedo
  float ambient = 0.45f;              ///< share of light that is not directional
  Vec3 light_dir_C{0.2, -0.6, -0.75}; ///< toward the light, camera frame
  double psf_sigma_px = 0.5;          ///< optical blur [px]; 0 = off
  double noise_sigma = 2.0;           ///< sensor noise [8-bit levels], i.i.d. per pixel and
                                      ///< channel within a frame; 0 = off
  int motion_blur_samples = 1;        ///< sub-frames per frame when a previous pose is given; 1 = off
  /// The user's elbows (left, right) [m, world]: each forearm points from its wrist toward its
  /// elbow, bending at the wrist at most max_wrist_bend_rad from the hand's axis
  /// (hand/forearm.hpp). Unset: the forearms stay in line with the hands.
  std::optional<std::array<Vec3, 2>> elbows_W;
  double max_wrist_bend_rad = 1.05;   ///< (0, π/2]: about 60°
  std::uint64_t seed = 1;             ///< noise seed (frames are reproducible)
};

/// Error naming the bad field.
Status validate(const SyntheticCameraParams& params);

struct SyntheticFrame {
  cv::Mat bgr;         ///< CV_8UC3, what the camera sees
  cv::Mat mask;        ///< CV_8UC1, 255 where a hand, bracelet or forearm is in front of the screen
  cv::Mat hand_index;  ///< CV_8UC1, 0 screen, 1 left hand, 2 right hand (incl. its bracelet/arm)
  cv::Mat hand_only;   ///< CV_8UC1, 255 where the hand itself (palm, digits) is in front: no
                       ///< bracelet, no forearm (what a hand model should cover)
  cv::Mat depth;       ///< CV_32FC1 z_C [m] of the ground-truth surface; +inf on the screen
  /// CV_8UC1, render::encode_hand_id of the part in front: the hand and its palm, digit (nails
  /// count as their digit), bracelet or forearm; 0 on the screen (hand_index and hand_only are
  /// made from it)
  cv::Mat hand_id;
  /// Where each forearm (left, right) pointed, from the wrist toward the elbow (unit, world);
  /// unset where it was in line with the hand (no elbows given) or the hand was not filmed.
  std::array<std::optional<Vec3>, 2> toward_elbow_W;
};

/// The poses to film: entry 0 left, 1 right; nullptr = that hand is out of view.
using HandPoses = std::array<const hand::HandParams*, 2>;

class SyntheticCamera {
 public:
  /// `truth` gives the two hands' shapes (left, right: the user's true proportions, not
  /// necessarily the registration's). The context must stay alive and current on this thread.
  /// A `camera` with lens distortion films through its lens: the colour image is bent as the lens
  /// bends it (vision::LensUndistortion::distort), while the ground truth (masks, ids, depth)
  /// stays in the view of its pinhole camera (vision::LensUndistortion), where the frames are
  /// undistorted into and the pipeline works. Error where the lens cannot be undistorted.
  static Result<std::unique_ptr<SyntheticCamera>> create(render::Context& context,
                                                         const vision::Camera& camera,
                                                         const std::array<hand::HandModel, 2>& truth,
                                                         const SyntheticCameraParams& params = {});
  ~SyntheticCamera();
  SyntheticCamera(const SyntheticCamera&) = delete;
  SyntheticCamera& operator=(const SyntheticCamera&) = delete;

  /// Films one frame at `poses`: film_image, then film_truth. With `previous` and
  /// motion_blur_samples > 1 the image is the mean of sub-frames from previous to poses (ground
  /// truth: at `poses`). Reuses out's buffers.
  Status film(const HandPoses& poses, SyntheticFrame* out, const HandPoses* previous = nullptr);
  /// What the camera delivers only: out->bgr and out->toward_elbow_W (the ground-truth images are
  /// left as they were). The ground truth of this film stays in the renderer for film_truth: a
  /// camera can hand the image over first and read its truth after (sim::CameraThread).
  Status film_image(const HandPoses& poses, SyntheticFrame* out, const HandPoses* previous = nullptr);
  /// The ground-truth images of the last film_image (out->mask, hand_index, hand_only, depth, hand_id).
  /// Error if there was none since the last film_truth, or the last film_image failed.
  Status film_truth(SyntheticFrame* out);

  /// The camera as given (with its lens, if any).
  const vision::Camera& camera() const;
  /// Another pose or calibration of the same image size (its lens as in create()).
  Status set_camera(const vision::Camera& camera);
  const SyntheticCameraParams& params() const;

 private:
  struct Impl;
  explicit SyntheticCamera(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace spidar::sim
