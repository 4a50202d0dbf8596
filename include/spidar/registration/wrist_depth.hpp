#pragma once
/// The wrist's other depth: four fingertips and the bracelet's pixel leave a hand two poses.
///
/// The strings fix the fingertips in 3D and the bracelet fixes the wrist's ray from the camera;
/// with the hand's size fixed, the wrist lies where that ray meets the sphere around the
/// fingertips whose radius is the wrist's distance from them: two points, one nearer the camera
/// than the other (docs/measurements.md, "The wrist's second depth"). A fit warm-started from the
/// previous frame stays at whichever one it was near, and the fingertips and the wrist pixel agree
/// with both. This gives the pose at the other one, to fit from and keep if it explains the image
/// better (the pipeline's FramePipelineParams::other_depth_every).
#include <optional>

#include "spidar/hand/hand_model.hpp"
#include "spidar/hand/parameters.hpp"
#include "spidar/registration/successive_adjustment.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::registration {

/// `q` turned about the centroid c of its own measured fingertips (those `obs` marks valid) so
/// that its wrist lies at the other intersection of the ray through obs.wrist_px with the sphere
/// about c through q's wrist; the fingers' angles are kept. Nothing (nullopt) without a wrist
/// pixel or fewer than three fingertips, when the ray misses the sphere, or when the two
/// intersections are less than `min_separation_m` apart [m] (no other pose to try).
std::optional<hand::HandParams> other_wrist_depth(const hand::HandModel& model, const hand::HandParams& q,
                                                  const HandObservation& obs, const vision::Camera& camera,
                                                  double min_separation_m = 0.02);

}  // namespace spidar::registration
