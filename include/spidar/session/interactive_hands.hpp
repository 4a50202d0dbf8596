#pragma once
/// The simulated user's hands under interactive control (hands.control: interactive): instead of
/// the Rubik's cube script, the GUI moves each hand (wrist position, yaw about the vertical) and
/// closes it (0 open … 1 closed). The hand posture follows from these controls; its fingertip
/// caps are the simulated device's goals (the device ties the caps to them through the
/// fingertip impedance, so contact forces push back) and the synthetic camera films the posture.
#include <array>

#include "spidar/core/seqlock.hpp"
#include "spidar/device/fingertip_source.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/hand/parameters.hpp"

namespace spidar::session {

struct HandControl {
  std::array<double, 3> offset_W{};  ///< wrist displacement from its start [m], world
  double yaw = 0;                    ///< rotation about world z [rad]
  double closeness = 0;              ///< 0 open … 1 closed
};
using HandControls = std::array<HandControl, 2>;  ///< left, right

class InteractiveHands final : public device::FingertipSource {
 public:
  /// `truth`: the user's hands; `open` and `closed`: postures (wrist pose of `open` is the start)
  /// between which `closeness` blends the finger angles.
  InteractiveHands(const std::array<hand::HandModel, 2>& truth,
                   const std::array<hand::HandParams, 2>& open,
                   const std::array<hand::HandParams, 2>& closed);
  /// Any thread (the GUI): the new controls (clamped: ±0.25 m, ±π, 0..1).
  void set(const HandControls& controls);
  HandControls controls() const;
  /// The posture of both hands for given controls.
  std::array<hand::HandParams, 2> pose(const HandControls& controls) const;
  /// Device thread: the eight caps (left thumb … ring, right thumb … ring) of pose(controls()).
  void goals(double t_s, std::span<Vec3> p_W_goal) override;
  const std::array<hand::HandModel, 2>& models() const { return truth_; }

 private:
  std::array<hand::HandModel, 2> truth_;
  std::array<hand::HandParams, 2> open_, closed_;
  core::Latest<HandControls> controls_;
};

}  // namespace spidar::session
