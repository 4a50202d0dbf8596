#include "allocation_counter.hpp"

#include <atomic>
#include <cstdlib>
#include <new>

#if defined(__SANITIZE_ADDRESS__)
#define SPIDAR_COUNT_ALLOCATIONS 0  // the ASan runtime owns operator new
#else
#define SPIDAR_COUNT_ALLOCATIONS 1
#endif

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_count{0};
thread_local bool t_marked = false;
}  // namespace

namespace spidar::testing::allocations {
bool available() { return SPIDAR_COUNT_ALLOCATIONS != 0; }
void mark_this_thread() { t_marked = true; }
void start() {
  g_count = 0;
  g_counting = true;
}
void stop() { g_counting = false; }
long count() { return g_count.load(); }
}  // namespace spidar::testing::allocations

#if SPIDAR_COUNT_ALLOCATIONS
void* operator new(std::size_t n) {
  if (t_marked && g_counting.load(std::memory_order_relaxed)) g_count.fetch_add(1);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#endif
