// Forward kinematics and Jacobians must not allocate (they run once per registration iteration
// and may run next to the servo loop). Counts global operator new calls around them.
#include <gtest/gtest.h>

#include "allocation_counter.hpp"
#include "hand_test_util.hpp"
#include "spidar/hand/kinematics.hpp"
#include "spidar/hand/projection.hpp"

namespace spidar::hand {
namespace {

TEST(NoAllocation, ForwardKinematicsAndJacobians) {
  namespace alloc = ::spidar::testing::allocations;
  if (!alloc::available()) GTEST_SKIP() << "allocation counting is off under ASan";
  alloc::mark_this_thread();
  std::mt19937 rng(1);
  for (auto side : {Side::kLeft, Side::kRight}) {
    const HandModel m = default_hand_model(side);
    const HandParams q = testing::random_params(m, rng);
    HandPoints p;
    FingertipJacobian Jt;
    JointJacobian Jj;
    alloc::start();
    forward_kinematics(m, q, &p, &Jt, &Jj);
    forward_kinematics(m, q, &p, nullptr, nullptr);
    const HandParams c = clamp_to_limits(q, m.limits);
    alloc::stop();
    EXPECT_EQ(alloc::count(), 0);
    EXPECT_TRUE(within_limits(c, m.limits));
  }
}

}  // namespace
}  // namespace spidar::hand
