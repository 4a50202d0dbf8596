#pragma once
// Two hands reaching over the frame centre, posed for the rig camera (shared by tests and bench).
#include <array>

#include "spidar/hand/hand_model.hpp"
#include "spidar/hand/parameters.hpp"

namespace spidar::render::test {

inline std::array<hand::HandParams, 2> reaching_hands(double dx = 0.0) {
  hand::HandParams right;
  right.set_wrist(Vec3(0.125 + dx, -0.05, 0.035), Vec3(0.0, 0.0, 1.1));
  right[hand::kThumbCmcFlexion] = 0.35;
  right[hand::kThumbCmcAbduction] = 0.45;
  right[hand::kThumbIp] = 0.3;
  for (int p : {hand::kIndexMcpFlexion, hand::kMiddleMcpFlexion, hand::kRingMcpFlexion}) right[p] = 0.55;
  for (int p : {hand::kIndexDip, hand::kMiddleDip, hand::kRingDip}) right[p] = 0.45;
  return {hand::mirror_params(right), right};
}

inline std::array<hand::HandModel, 2> truth_models() {
  hand::HandDimensions dims;
  dims.length = 0.182;
  dims.width = 0.081;
  return {hand::make_hand_model(hand::Side::kLeft, dims).value(),
          hand::make_hand_model(hand::Side::kRight, dims).value()};
}

}  // namespace spidar::render::test
