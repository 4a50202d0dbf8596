#pragma once
/// The inputs every rig loads the same way: the camera scaled to the run's image size and the
/// hands of a profile.
#include <array>
#include <string>

#include "spidar/hand/hand_model.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::session {

/// The camera with its intrinsics scaled to a w×h image (pixel centres kept consistent).
vision::Camera scaled_camera(const vision::Camera& c, int w, int h);

/// Both hands (left, right) of profile `profile` in a hands YAML. With `first_if_missing`, a
/// missing profile falls back to the file's first one; otherwise SpidarError naming the file
/// (bad input: the CLI exits with code 2).
std::array<hand::HandModel, 2> hand_models(const std::string& path, const std::string& profile,
                                           bool first_if_missing);

}  // namespace spidar::session
