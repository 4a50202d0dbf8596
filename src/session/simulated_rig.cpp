#include "spidar/session/rig.hpp"

namespace spidar::session {

SimulatedRig::SimulatedRig(const strings::DeviceConfig& config, const Scene& scene,
                           const vision::Camera& camera, const std::array<hand::HandModel, 2>& user,
                           const SimulatedRigParams& params, std::unique_ptr<FrameSource> other_camera)
    : config_(config), user_(user) {
  std::shared_ptr<device::FingertipSource> goals = scene.task;
  if (params.interactive) {
    // Open: the script's start (withdrawn, relaxed); closed: its grip on the cube.
    std::array<hand::HandParams, 2> open, closed;
    for (int h = 0; h < 2; ++h) {
      const auto side = h == 0 ? hand::Side::kLeft : hand::Side::kRight;
      open[h] = scene.task->nominal(0.0, side);
      closed[h] = scene.task->nominal(2.0, side);
    }
    interactive_ = std::make_shared<InteractiveHands>(user, open, closed);
    goals = interactive_;
  }
  device::SimulatedSpidarParams dp;
  dp.seed = params.seed;
  device_ = std::make_unique<device::SimulatedSpidar>(config_, dp, goals);
  if (other_camera) {
    camera_ = std::move(other_camera);
  } else if (interactive_) {
    camera_ = make_interactive_source(camera, *interactive_, params.fps, params.seed);
  } else {
    camera_ = make_synthetic_source(camera, user, *scene.task, *device_, params.fps, params.seed,
                                    params.bending_wrists);
  }
}

}  // namespace spidar::session
