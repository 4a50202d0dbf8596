#pragma once
/// One hand as the kinematics sees it: which side, the user's shape, the coupling of the last two
/// joints and the parameter limits.
#include "spidar/core/result.hpp"
#include "spidar/hand/coupling.hpp"
#include "spidar/hand/hand_shape.hpp"
#include "spidar/hand/joint_limits.hpp"
#include "spidar/hand/parameters.hpp"

namespace spidar::hand {

struct HandModel {
  Side side = Side::kRight;
  Coupling coupling = Coupling::kPaperQuadratic;
  HandShape shape;     ///< right-hand numbers; mirrored in x_H for the left hand
  ParamLimits limits;  ///< from the joint ranges under `coupling`
};

/// Builds a model. Fails (naming what) on invalid dimensions or joint ranges.
Result<HandModel> make_hand_model(Side side, const HandDimensions& dims = {},
                                  Coupling coupling = Coupling::kPaperQuadratic,
                                  const JointRanges& ranges = {});

/// The default model hand of one side (0.19 m, paper's coupling, default ranges).
HandModel default_hand_model(Side side, Coupling coupling = Coupling::kPaperQuadratic);

}  // namespace spidar::hand
