#include "spidar/hand/hand_model.hpp"

namespace spidar::hand {

Result<HandModel> make_hand_model(Side side, const HandDimensions& dims, Coupling coupling,
                                  const JointRanges& ranges) {
  if (auto s = validate_joint_ranges(ranges); !s.ok()) return s.error();
  auto shape = make_hand_shape(dims);
  if (!shape.ok()) return shape.error();
  HandModel model;
  model.side = side;
  model.coupling = coupling;
  model.shape = *shape;
  model.limits = parameter_limits(ranges, coupling);
  return model;
}

HandModel default_hand_model(Side side, Coupling coupling) {
  HandModel model;
  model.side = side;
  model.coupling = coupling;
  model.shape = default_hand_shape();
  model.limits = parameter_limits(JointRanges{}, coupling);
  return model;
}

}  // namespace spidar::hand
