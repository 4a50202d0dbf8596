// Forward kinematics and Jacobians must not allocate (they run once per registration iteration
// and may run next to the servo loop). Counts global operator new calls around them.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "hand_test_util.hpp"
#include "spidar/hand/kinematics.hpp"
#include "spidar/hand/projection.hpp"

// Under AddressSanitizer the runtime owns operator new; the count is skipped there.
#if defined(__SANITIZE_ADDRESS__)
#define SPIDAR_COUNT_ALLOCATIONS 0
#else
#define SPIDAR_COUNT_ALLOCATIONS 1
#endif

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

#if SPIDAR_COUNT_ALLOCATIONS
void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
#endif

namespace spidar::hand {
namespace {

TEST(NoAllocation, ForwardKinematicsAndJacobians) {
  if (!SPIDAR_COUNT_ALLOCATIONS) GTEST_SKIP() << "allocation counting is off under ASan";
  std::mt19937 rng(1);
  for (auto side : {Side::kLeft, Side::kRight}) {
    const HandModel m = default_hand_model(side);
    const HandParams q = testing::random_params(m, rng);
    HandPoints p;
    FingertipJacobian Jt;
    JointJacobian Jj;
    const long before = g_allocations.load();
    forward_kinematics(m, q, &p, &Jt, &Jj);
    forward_kinematics(m, q, &p, nullptr, nullptr);
    const HandParams c = clamp_to_limits(q, m.limits);
    const long after = g_allocations.load();
    EXPECT_EQ(after - before, 0);
    EXPECT_TRUE(within_limits(c, m.limits));
  }
}

}  // namespace
}  // namespace spidar::hand
