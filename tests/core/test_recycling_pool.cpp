#include "spidar/core/recycling_pool.hpp"

#include <gtest/gtest.h>

#include <condition_variable>
#include <deque>
#include <thread>
#include <vector>

namespace spidar::core {
namespace {

TEST(RecyclingPool, ALetGoObjectComesBackWithItsStorage) {
  RecyclingPool<std::vector<int>> pool;
  auto a = pool.take();
  a->assign(1000, 7);
  const int* storage = a->data();
  const std::vector<int>* address = a.get();
  a.reset();
  EXPECT_EQ(pool.free(), 1u);
  auto b = pool.take();
  EXPECT_EQ(b.get(), address);
  EXPECT_EQ(b->data(), storage);  // the storage came back too: nothing to allocate
  EXPECT_EQ(b->size(), 1000u);
  EXPECT_EQ(pool.created(), 1u);
}

TEST(RecyclingPool, AHeldObjectIsNeverHandedOut) {
  RecyclingPool<int> pool;
  auto a = pool.take();
  auto copy = a;  // two holders
  a.reset();
  auto b = pool.take();
  EXPECT_NE(b.get(), copy.get());
  EXPECT_EQ(pool.created(), 2u);
  copy.reset();
  auto c = pool.take();
  EXPECT_NE(c.get(), b.get());
  EXPECT_EQ(pool.created(), 2u);  // the first came back once its last holder let go
}

TEST(RecyclingPool, AHolderMayOutliveThePool) {
  std::shared_ptr<std::vector<int>> kept;
  {
    RecyclingPool<std::vector<int>> pool;
    kept = pool.take();
    kept->assign(10, 1);
  }
  EXPECT_EQ(kept->size(), 10u);
  kept.reset();  // deleted, not returned (ASan: no leak, no use after free)
}

// One producer fills objects with a pattern unique to each frame and hands them to a consumer that
// reads them slowly while the producer goes on: every object the consumer reads still holds its
// own frame's pattern (it would not if the pool handed out an object still held), and the pool
// makes no more objects than are held at once. Run under TSan in CI (the threaded test set).
TEST(RecyclingPool, ObjectsHandedToAnotherThreadAreNotOverwrittenWhileHeld) {
  RecyclingPool<std::vector<int>> pool;
  std::mutex m;
  std::condition_variable cv;
  std::deque<std::shared_ptr<const std::vector<int>>> queue;
  bool done = false;
  constexpr int kFrames = 400, kQueue = 3;
  int bad = 0, seen = 0;
  std::thread consumer([&] {
    for (;;) {
      std::shared_ptr<const std::vector<int>> v;
      {
        std::unique_lock lock(m);
        cv.wait(lock, [&] { return done || !queue.empty(); });
        if (queue.empty()) return;
        v = std::move(queue.front());
        queue.pop_front();
      }
      cv.notify_all();
      const int frame = v->front();
      for (int x : *v) bad += x != frame ? 1 : 0;
      ++seen;
    }
  });
  for (int f = 0; f < kFrames; ++f) {
    auto v = pool.take();
    v->assign(4096, f);
    std::unique_lock lock(m);
    cv.wait(lock, [&] { return queue.size() < kQueue; });
    queue.push_back(std::move(v));
    cv.notify_all();
  }
  {
    std::lock_guard lock(m);
    done = true;
  }
  cv.notify_all();
  consumer.join();
  EXPECT_EQ(seen, kFrames);
  EXPECT_EQ(bad, 0);
  // At most the queue's objects, the one the consumer reads and the one being filled.
  EXPECT_LE(pool.created(), static_cast<std::size_t>(kQueue + 2));
}

}  // namespace
}  // namespace spidar::core
