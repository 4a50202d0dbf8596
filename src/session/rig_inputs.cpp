#include "spidar/session/rig_inputs.hpp"

#include "spidar/core/config.hpp"
#include "spidar/core/result.hpp"
#include "spidar/hand/hand_config.hpp"
#include "spidar/registration/registration_params.hpp"
#include "spidar/vision/vision_config.hpp"

namespace spidar::session {

vision::Camera scaled_camera(const vision::Camera& c, int w, int h) {
  vision::Intrinsics k = c.intrinsics();
  const double sx = static_cast<double>(w) / k.width, sy = static_cast<double>(h) / k.height;
  k.fx *= sx;
  k.fy *= sy;
  k.cx = (k.cx + 0.5) * sx - 0.5;
  k.cy = (k.cy + 0.5) * sy - 0.5;
  k.width = w;
  k.height = h;
  return vision::Camera(k, c.X_CW());
}

std::array<hand::HandModel, 2> hand_models(const std::string& path, const std::string& profile,
                                           bool first_if_missing, std::string* chosen) {
  const hand::HandProfiles profiles = hand::load_hand_profiles(path);  // throws ConfigError
  const hand::HandProfile* p = profiles.find(profile);
  if (p == nullptr) {
    if (!first_if_missing || profiles.profiles.empty())
      throw SpidarError(path + ": no hand profile '" + profile + "'");
    p = &profiles.profiles.front();
  }
  if (chosen) *chosen = p->name;
  return {p->model(hand::Side::kLeft), p->model(hand::Side::kRight)};
}

pipeline::FramePipelineParams pipeline_params(const std::string& vision_yaml,
                                              const std::string& registration_yaml,
                                              bool silhouette, render::CompositeMode mode,
                                              const std::array<Vec3, 2>& initial_r_W_hand) {
  const auto vision_cfg = vision::load_vision_config(vision_yaml);
  const auto reg_root = core::ConfigNode::LoadFile(registration_yaml);
  pipeline::FramePipelineParams pp;
  pp.chroma_key = vision_cfg.chroma_key;
  pp.bracelet = vision_cfg.bracelet;
  pp.registration = registration::parse_registration_params(reg_root["registration"]);
  pp.registration.silhouette_term = silhouette;
  if (auto node = reg_root.find("personalisation"))
    pp.shape_estimator = registration::parse_shape_estimator_params(*node, &pp.personalise_shape);
  pp.compositor.mode = mode;
  pp.initial_r_W_hand = initial_r_W_hand;
  return pp;
}

}  // namespace spidar::session
