#pragma once
/// The scripted user of the haptic demo: goal positions for the eight fingertips (left thumb,
/// index, middle, ring, then right) around a Rubik's cube, as functions of time.
///
///   0 – 1 s  hands approach           1 – 2 s  both hands close on the cube
///   2 – 3 s  lift by `lift` (left hand holds the two lower layers, right hand the top layer)
///   3 – 5.5 s the right hand turns the top layer by `turn` about +z
///   5.5 – 6.5 s the right hand lets go   6.5 – 7.5 s the left hand sets the cube down, opens
///
/// Goals lie `squeeze` inside the faces: the simulated fingertip yields to the displayed force
/// through its impedance, so the goal's depth sets the grip force.
#include <span>
#include <string>

#include "spidar/core/types.hpp"
#include "spidar/device/fingertip_source.hpp"

namespace spidar::sim {

struct RubiksScriptParams {
  Vec3 p_W_cube = Vec3::Zero();  ///< cube centre at the start [m]
  double half = 0.0285;          ///< half the cube's size [m]
  double pitch = 0.019;          ///< layer pitch [m]
  double proxy_radius = 0.008;   ///< [m]
  double squeeze = 0.012;        ///< goal depth inside the faces [m]
  double lift = 0.02;            ///< [m]
  double turn = 1.75;            ///< [rad], past 90° so the detent finishes the click
  double duration = 7.5;         ///< [s]
};

class RubiksScript final : public device::FingertipSource {
 public:
  explicit RubiksScript(RubiksScriptParams p) : p_(p) {}
  void goals(double t_s, std::span<Vec3> p_W_goal) override;
  /// Name of the phase at time t (for progress output).
  static const char* phase(double t_s);
  const RubiksScriptParams& params() const { return p_; }

 private:
  RubiksScriptParams p_;
};

}  // namespace spidar::sim
