#pragma once
/// The inputs every session loads the same way: the camera scaled to the run's image size, the
/// hands of a profile, and the frame pipeline's parameters from the vision and registration
/// configs.
#include <array>
#include <string>

#include "spidar/core/types.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/pipeline/frame_pipeline.hpp"
#include "spidar/render/compositor.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::session {

/// The camera with its intrinsics scaled to a w×h image (pixel centres kept consistent).
vision::Camera scaled_camera(const vision::Camera& c, int w, int h);

/// Both hands (left, right) of profile `profile` in a hands YAML. With `first_if_missing`, a
/// missing profile falls back to the file's first one; otherwise SpidarError naming the file
/// (bad input: the CLI exits with code 2). `chosen` (optional): the name of the profile used.
std::array<hand::HandModel, 2> hand_models(const std::string& path, const std::string& profile,
                                           bool first_if_missing, std::string* chosen = nullptr);

/// The frame pipeline's parameters: chroma key and bracelet from `vision_yaml`, registration from
/// `registration_yaml` (key `registration`) with the silhouette term on or off, the compositor
/// mode, and the wrists' start rotation vectors (left, right; world frame [rad]). Throws
/// core::ConfigError naming file, line and key.
pipeline::FramePipelineParams pipeline_params(const std::string& vision_yaml,
                                              const std::string& registration_yaml,
                                              bool silhouette, render::CompositeMode mode,
                                              const std::array<Vec3, 2>& initial_r_W_hand);

}  // namespace spidar::session
