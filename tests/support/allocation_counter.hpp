#pragma once
/// Counts heap allocations (operator new) made by marked threads while counting is on. Link
/// allocation_counter.cpp into the test binary. Under AddressSanitizer the runtime owns operator
/// new, so counting is unavailable there (`available()` is false and tests should skip).
namespace spidar::testing::allocations {

bool available();
/// Marks the calling thread as one whose allocations count.
void mark_this_thread();
/// Starts counting from zero / stops counting.
void start();
void stop();
long count();

}  // namespace spidar::testing::allocations
