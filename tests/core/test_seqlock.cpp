#include <gtest/gtest.h>

#include <atomic>
#include <memory>
#include <span>
#include <vector>
#include <thread>

#include "spidar/core/seqlock.hpp"

namespace spidar::core {
namespace {

/// A value whose fields must always agree: a torn read would break the invariant.
struct Checked {
  std::uint64_t n = 0;
  double a[16] = {};
  std::uint64_t check = 0;
};
Checked make(std::uint64_t n) {
  Checked c;
  c.n = n;
  for (int i = 0; i < 16; ++i) c.a[i] = static_cast<double>(n * 16 + i);
  c.check = ~n;
  return c;
}
bool intact(const Checked& c) {
  for (int i = 0; i < 16; ++i)
    if (c.a[i] != static_cast<double>(c.n * 16 + i)) return false;
  return c.check == ~c.n;
}

TEST(Latest, EmptyThenNewest) {
  Latest<Checked> l;
  EXPECT_FALSE(l.read().has_value());
  l.publish(make(3));
  l.publish(make(4));
  ASSERT_TRUE(l.read().has_value());
  EXPECT_EQ(l.read()->n, 4u);
}

TEST(Latest, ConcurrentReadsAreNeverTornAndNeverGoBack) {
  Latest<Checked> l;
  std::atomic<bool> done{false};
  std::atomic<std::uint64_t> reads{0}, written{0};
  // The writer keeps publishing until the reader has read many times while it writes. It yields
  // now and then: back-to-back publishes can keep a reader slowed by a sanitizer from ever
  // reading between two of them, and the test would then run to the cap and fail.
  std::thread writer([&] {
    std::uint64_t n = 1;
    for (; reads.load() < 20000 && n < 50'000'000; ++n) {
      l.publish(make(n));
      if (n % 256 == 0) std::this_thread::yield();
    }
    written = n - 1;
    done = true;
  });
  std::uint64_t last = 0;
  while (!done) {
    if (auto v = l.read()) {
      ASSERT_TRUE(intact(*v));
      ASSERT_GE(v->n, last);
      last = v->n;
      reads.fetch_add(1);
    }
  }
  writer.join();
  EXPECT_EQ(l.read()->n, written.load());
  EXPECT_GE(reads.load(), 20000u);
}

TEST(SampleRing, NewestFirstAndOverwritesOldest) {
  SampleRing<Checked, 8> ring;
  Checked out[8];
  EXPECT_EQ(ring.newest(out, 8), 0u);
  for (std::uint64_t n = 0; n < 20; ++n) ring.push(make(n));
  EXPECT_EQ(ring.count(), 20u);
  const auto k = ring.newest(out, 8);
  ASSERT_EQ(k, 7u);  // N − 1: the slot being written next is never read
  for (std::size_t i = 0; i < k; ++i) EXPECT_EQ(out[i].n, 19 - i);
}

TEST(SampleRing, ConcurrentReadersSeeConsecutiveIntactSamples) {
  SampleRing<Checked, 64> ring;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (std::uint64_t n = 0; n < 100000; ++n) ring.push(make(n));
    done = true;
  });
  Checked out[16];
  while (!done) {
    const auto k = ring.newest(out, 16);
    for (std::size_t i = 0; i < k; ++i) {
      ASSERT_TRUE(intact(out[i]));
      if (i > 0) {
        ASSERT_EQ(out[i - 1].n, out[i].n + 1);
      }
    }
  }
  writer.join();
}

// read_newest_until reads only as far back as the reader needs: values after the last one it
// handled, in growing tries, and everything (up to its buffer) the first time.
TEST(SampleRing, ReadNewestUntilStopsWhereTheReaderLeftOff) {
  auto ring = std::make_unique<SampleRing<std::uint64_t, 4096>>();
  for (std::uint64_t v = 1; v <= 3000; ++v) ring->push(v);
  std::vector<std::uint64_t> buf(4096);
  std::vector<std::size_t> asked;
  auto read = [&](std::uint64_t* out, std::size_t max) {
    asked.push_back(max);
    return ring->newest(out, max);
  };
  // Handled up to 2990: the first 32 reach it.
  std::size_t n = read_newest_until(read, std::span(buf), [](std::uint64_t v) { return v <= 2990; });
  EXPECT_EQ(n, 32u);
  EXPECT_EQ(buf[0], 3000u);
  EXPECT_EQ(asked, (std::vector<std::size_t>{32}));
  // Handled up to 2900: 32, then 128.
  asked.clear();
  n = read_newest_until(read, std::span(buf), [](std::uint64_t v) { return v <= 2900; });
  EXPECT_EQ(n, 128u);
  EXPECT_LE(buf[n - 1], 2900u);
  EXPECT_EQ(asked, (std::vector<std::size_t>{32, 128}));
  // Nothing handled yet: all the ring has, in tries that stop when it has no more.
  asked.clear();
  n = read_newest_until(read, std::span(buf), [](std::uint64_t) { return false; });
  EXPECT_EQ(n, 3000u);
  EXPECT_EQ(buf[n - 1], 1u);
  EXPECT_EQ(asked, (std::vector<std::size_t>{32, 128, 512, 2048, 4096}));
  // A buffer smaller than the need: full, then no more tries.
  std::vector<std::uint64_t> small(100);
  asked.clear();
  EXPECT_EQ(read_newest_until(read, std::span(small), [](std::uint64_t) { return false; }), 100u);
  EXPECT_EQ(asked, (std::vector<std::size_t>{32, 100}));
  std::vector<std::uint64_t> none;
  EXPECT_EQ(read_newest_until(read, std::span(none), [](std::uint64_t) { return false; }), 0u);
}

}  // namespace
}  // namespace spidar::core
