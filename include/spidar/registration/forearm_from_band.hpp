#pragma once
/// Where a forearm points, from its bracelet's band in the image. The 17-DOF hand has no wrist
/// joint; the registration puts the bracelet along the forearm it is given
/// (HandObservation::forearm_H), in line with the hand unless told otherwise. A real wrist bends
/// by tens of degrees, mostly toward or away from the camera when the hands work on a table below
/// it, and the forearm's direction in the image alone cannot show that.
///
/// The band can: it is a ring around the forearm (registration_params.hpp's section, width
/// bracelet_width_m), and how thick it looks across its long axis says how obliquely the camera
/// sees the forearm (a thin strip from the side, a full ring end-on); its long axis lies across the
/// forearm's image direction. Each candidate direction within the wrist's bend (a cone about the
/// hand's axis) predicts both for the band around that forearm (hand::wrist_bend applied to the
/// hand's pose); the estimate is the candidate whose prediction is nearest the detection, with a
/// prior toward the in-line forearm and one toward the previous frame's estimate. The two signs of
/// a tilt, toward or away from the camera, give nearly the same thickness and axis; the side to
/// which the crescent (the band's near side seen obliquely) bulges tells them apart, as far as
/// the band is not seen end-on. A search, not a descent: the cost has a minimum for each sign.
#include <optional>

#include "spidar/core/types.hpp"
#include "spidar/registration/registration_params.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::registration {

/// The candidates: a coarse grid of bends 0 .. RegistrationParams::forearm_max_bend_rad in this
/// many steps, each (but 0) at this many directions around the hand's axis, and the last estimate;
/// then this many rounds of the 8 neighbours of the best, at half the grid's steps and halving.
inline constexpr int kForearmBendSteps = 4;
inline constexpr int kForearmAzimuthSteps = 8;
inline constexpr int kForearmRefinements = 3;
/// Points around each rim of a candidate's band (bracelet_band_profile): 15° apart, its extent
/// within 1 % of the band's radius.
inline constexpr int kForearmBandSamplesPerRim = 32;
/// A band less solid than this (its red share of its oriented box) is no evidence: torn or mostly
/// hidden. A crescent, the band's near side seen obliquely, fills about 0.35 of its box.
inline constexpr double kForearmBandMinFill = 0.2;

/// The detected band (vision::BraceletObservation's fields).
struct BandObservation {
  Vec2 end_a_px = Vec2::Zero(), end_b_px = Vec2::Zero();  ///< ends along its long axis [px]
  double length_px = 0;     ///< extent along the long axis [px]
  double thickness_px = 0;  ///< extent across it [px]
  double fill = 0;          ///< share of its oriented box that is red, 0..1
  /// The red's centroid minus the middle of its extent across the long axis, along
  /// (−u_y, u_x) for u the unit from end_a_px to end_b_px [px] (a crescent's bulge).
  double bulge_px = 0;
};

/// The forearm's direction (right-hand H coordinates, unit, toward the elbow) for a hand at pose
/// X_WH of width hand_width_m [m], seen by `camera`, from its detected band; `previous_H` the last
/// estimate (H coordinates) or null. Uses the band's geometry (bracelet_*) and the forearm_*
/// settings of `params`. nullopt where the band is no evidence (torn, degenerate, not finite) or
/// no candidate's band is in front of the camera.
std::optional<Vec3> forearm_from_band(const Pose& X_WH, double hand_width_m, const vision::Camera& camera,
                                      const RegistrationParams& params, const BandObservation& band,
                                      const Vec3* previous_H);

}  // namespace spidar::registration
