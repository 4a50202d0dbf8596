#pragma once
/// A lens's distortion taken out of its frames (and, for the simulated camera, put into them).
///
/// The renderer, the compositor and the keyed images the registration reads are pinhole: the
/// virtual world is drawn with K alone. A real camera's lens bends straight lines (a webcam's
/// barrel distortion moves the image's corners by 10–30 px at 640×480), so its raw frame and the
/// rendered world would disagree there. The frames are therefore undistorted once, when they
/// arrive, into the image of a pinhole camera (`pinhole()`: the same size and pose, no
/// distortion, its K chosen so that every one of its pixels is seen by the sensor:
/// cv::getOptimalNewCameraMatrix with alpha 0), and everything downstream works with that camera.
///
/// Pixel convention as vision::Camera (pixel (0, 0) is the centre of the top-left pixel).
#include <optional>

#include <opencv2/core.hpp>

#include "spidar/core/result.hpp"
#include "spidar/core/types.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::vision {

class LensUndistortion {
 public:
  /// From a calibration with distortion (`lens`; validate_intrinsics must accept it). Error, naming
  /// the coefficients, where the lens folds the image (its radial mapping is not increasing out to
  /// the image's corners) or a pinhole view seen whole by the sensor would keep less than
  /// half of its field of view: no real lens does either, a calibration gone wrong does.
  static Result<LensUndistortion> create(const Intrinsics& lens);
  /// create()'s checks alone, without making the tables (93 ms at 640×480): for refusing bad input
  /// early.
  static Status check(const Intrinsics& lens);
  /// The lens of a calibration: none without distortion, else create()'s (or its error).
  static Result<std::optional<LensUndistortion>> of(const Intrinsics& calibration);

  /// The calibration given (with its distortion).
  const Intrinsics& lens() const { return lens_; }
  /// The pinhole camera's intrinsics: the lens's image size, no distortion.
  const Intrinsics& pinhole() const { return pinhole_; }
  /// The pinhole camera at the lens camera's pose `X_CW` (undistortion does not turn the view).
  Camera pinhole_camera(const Pose& X_CW) const { return Camera(pinhole_, X_CW); }

  /// The sensor's frame (lens().width × lens().height, any depth and channel count) → the pinhole
  /// camera's image, bilinear. Reuses `pinhole_image`'s buffer.
  void undistort(const cv::Mat& sensor, cv::Mat* pinhole_image) const;
  /// The pinhole camera's image → what the sensor films through the lens, bilinear; sensor pixels
  /// that see beyond the pinhole view get `outside`. (The simulated camera's lens.)
  void distort(const cv::Mat& pinhole_image, cv::Mat* sensor, const cv::Scalar& outside) const;

  /// Where a sensor pixel lies in the pinhole image, and the reverse [px] (the maps' own math:
  /// cv::undistortPoints, and vision::Camera's projection with the lens).
  Vec2 to_pinhole(const Vec2& sensor_px) const;
  Vec2 to_sensor(const Vec2& pinhole_px) const;

 private:
  LensUndistortion() = default;
  /// The checks and the pinhole intrinsics (create()'s first half).
  static Result<Intrinsics> pinhole_of(const Intrinsics& lens);
  Intrinsics lens_, pinhole_;
  cv::Mat undistort_xy_, undistort_frac_;  ///< cv::remap maps, pinhole pixel → sensor (CV_16SC2, CV_16UC1)
  cv::Mat distort_xy_, distort_frac_;      ///< sensor pixel → pinhole
};

}  // namespace spidar::vision
