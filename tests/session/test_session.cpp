// A Session on the simulated rig, headless and short: the fan-out to the sinks, the bounded
// history, the warm-up, and a sink that throws.
#include <gtest/gtest.h>

#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <string>
#include <thread>
#include <stdexcept>
#include <vector>

#include "named_thread.hpp"
#include "spidar/core/realtime.hpp"
#include "spidar/session/async_sinks.hpp"
#include "spidar/session/frame_stats.hpp"
#include "spidar/session/session.hpp"
#include "spidar/sim/camera_thread.hpp"
#include "after_frames.hpp"
#include "simulated_setup.hpp"

namespace spidar::session {
namespace {

/// Writes down what it sees: the order of the calls, each frame's index and time.
struct TracingSink final : FrameSink {
  void on_start() override { calls.push_back('s'); }
  void on_frame(const FrameEvent& e) override {
    calls.push_back('f');
    indices.push_back(e.index);
    times.push_back(e.t_s);
    cold.push_back(e.cold_start);
    frame_thread_nice.push_back(getpriority(PRIO_PROCESS, static_cast<id_t>(gettid())));
    truth.push_back(e.filmed != nullptr);
  }
  void on_end(const SessionSummary& s) override {
    calls.push_back('e');
    summary = s;
  }
  std::string calls;
  std::vector<std::uint64_t> indices;
  std::vector<double> times;
  std::vector<bool> cold, truth;
  std::vector<int> frame_thread_nice;  ///< the calling (frame) thread's niceness at each frame
  SessionSummary summary;
};

using testing::after_frames;

/// Generous: only a run that never gets its frames reaches it.
constexpr double kBackstopS = 30.0;

TEST(Session, EverySinkSeesEveryProcessedFrameInOrderWithIncreasingTimes) {
  SimulatedSetup s(2.5);
  TracingSink a, b;
  s.session->add_sink(a);
  s.session->add_sink(b);
  const SessionSummary end = s.session->run();
  // Order and times need two frames; how many a 2.5 s run processes is speed (5 in 1.5 s under ASan).
  ASSERT_GE(end.frames, 2u) << "a 2.5 s run at 30 fps processes frames";
  EXPECT_EQ(end.ended_by, "completed");
  EXPECT_TRUE(end.camera_error.empty()) << end.camera_error;
  EXPECT_GE(end.camera_frames, end.frames);
  for (const TracingSink* k : {&a, &b}) {
    EXPECT_EQ(k->calls, "s" + std::string(end.frames, 'f') + "e");
    ASSERT_EQ(k->indices.size(), end.frames);
    for (std::size_t i = 0; i < k->indices.size(); ++i) EXPECT_EQ(k->indices[i], i);
    for (std::size_t i = 1; i < k->times.size(); ++i) EXPECT_GT(k->times[i], k->times[i - 1]) << i;
    EXPECT_LE(k->times.back(), 2.5) << "frames past SessionParams::seconds end the run";
    for (bool t : k->truth) EXPECT_TRUE(t) << "the synthetic camera's frames carry the truth";
    EXPECT_EQ(k->summary.frames, end.frames);
  }
  EXPECT_EQ(a.times, b.times);
  // The frame thread runs at SessionParams::frame_nice where that is permitted (root here).
  if (geteuid() == 0) {
    for (int n : a.frame_thread_nice) EXPECT_EQ(n, SessionParams{}.frame_nice);
  }
  // Stopped: a second stop() returns the same summary and calls no sink again.
  EXPECT_EQ(s.session->stop().frames, end.frames);
  EXPECT_EQ(a.calls.back(), 'e');
  EXPECT_EQ(std::count(a.calls.begin(), a.calls.end(), 'e'), 1);
  EXPECT_FALSE(s.session->running());
}

/// The names of the process's threads now (/proc/self/task/*/comm).
std::vector<std::string> thread_names() {
  std::vector<std::string> out;
  for (const auto& task : std::filesystem::directory_iterator("/proc/self/task")) {
    std::ifstream in(task.path() / "comm");
    std::string name;
    if (std::getline(in, name)) out.push_back(name);
  }
  return out;
}

// A running session's threads carry their roles' names (core::set_thread_name), so that `top -H`,
// `ps -L`, perf and gdb tell them apart on a busy machine.
TEST(Session, ItsThreadsAreNamedForTheirRoles) {
  SimulatedSetup s(kBackstopS);
  // Each thread names itself when it starts, which a loaded machine may delay past the first
  // frames: the names are read at each frame until every role has shown up (or 60 frames).
  const std::vector<std::string> roles{"spidar-servo", "spidar-watchdog", "spidar-physics", "spidar-camera"};
  std::vector<std::string> seen;
  std::size_t frames = 0;
  auto all_named = [&] {
    for (const std::string& role : roles)
      if (std::find(seen.begin(), seen.end(), role) == seen.end()) return false;
    return true;
  };
  FunctionSink look([&](const FrameEvent&) {
    ++frames;
    if (!all_named()) seen = thread_names();
  });
  s.session->add_sink(look);
  (void)s.session->run([&]() -> std::optional<std::string> {
    if (all_named() || frames >= 60) return std::string("looked");
    return std::nullopt;
  });
  ASSERT_GT(frames, 0u) << "no frame processed";
  for (const std::string& role : roles)
    EXPECT_NE(std::find(seen.begin(), seen.end(), role), seen.end()) << role;
}

/// Whether this process may give a thread SCHED_FIFO (root, CAP_SYS_NICE or an rtprio limit).
bool fifo_permitted() {
  bool ok = false;
  std::thread([&ok] { ok = core::set_fifo_priority(1).ok(); }).join();
  return ok;
}

// On a busy machine the frame thread and the simulated camera lost their CPU to any other
// program at nice 0 (latency p95 51–62 ms, one core busy); at SCHED_FIFO 20 and 30 they do not
// (25–32 ms). The caller's own scheduling comes back when run() returns.
TEST(Session, TheFrameThreadAndTheCameraRunAtTheirRealTimePrioritiesAndTheCallersComesBack) {
  if (!fifo_permitted()) GTEST_SKIP() << "SCHED_FIFO not permitted here";
  SimulatedSetup s(kBackstopS);
  const core::ThreadScheduling before = core::current_scheduling();
  std::vector<core::ThreadScheduling> frame_thread;
  int camera_policy = -1, camera_priority = -1;
  FunctionSink look([&](const FrameEvent&) {
    frame_thread.push_back(core::current_scheduling());
    if (const pid_t camera = spidar::test::thread_named("spidar-camera"); camera > 0) {
      sched_param sp{};
      camera_policy = sched_getscheduler(camera);
      if (sched_getparam(camera, &sp) == 0) camera_priority = sp.sched_priority;
    }
  });
  s.session->add_sink(look);
  const SessionSummary end = s.session->run([&]() -> std::optional<std::string> {
    if (frame_thread.size() >= 5) return std::string("looked");
    return std::nullopt;
  });
  ASSERT_FALSE(frame_thread.empty()) << "no frame processed";
  for (const core::ThreadScheduling& f : frame_thread) {
    EXPECT_EQ(f.policy, SCHED_FIFO);
    EXPECT_EQ(f.priority, SessionParams{}.frame_fifo_priority);
  }
  EXPECT_TRUE(end.frame_realtime);
  EXPECT_EQ(camera_policy, SCHED_FIFO);
  EXPECT_EQ(camera_priority, sim::CameraThreadParams{}.fifo_priority);
  EXPECT_EQ(core::current_scheduling(), before) << "run() left the caller's thread at the frame thread's scheduling";
}

TEST(Session, APriorityOutsideItsRangeIsRefusedByName) {
  using Tweak = std::function<void(SessionParams&, int)>;
  const std::vector<std::pair<std::string, Tweak>> fields{
      {"frame_fifo_priority must be in 0..99", [](SessionParams& p, int v) { p.frame_fifo_priority = v; }},
      {"physics_priority must be in 0..99", [](SessionParams& p, int v) { p.physics_priority = v; }}};
  for (const auto& [message, set] : fields) {
    for (int bad : {-1, 100}) {
      SessionParams p;
      ASSERT_TRUE(validate(p).ok());
      set(p, bad);
      const Status st = validate(p);
      ASSERT_FALSE(st.ok()) << message << ": " << bad << " was accepted";
      EXPECT_NE(st.error().message.find(message), std::string::npos) << st.error().message;
    }
  }
}

TEST(Session, WarmUpHappensOnceAndTheFirstRealFrameIsAColdStart) {
  SimulatedSetup s(kBackstopS);
  TracingSink k;
  s.session->add_sink(k);
  s.session->start();
  s.session->start();  // idempotent: no second warm-up
  EXPECT_EQ(s.session->warm_ups(), 1);
  const SessionSummary end = s.session->run(after_frames(3, [&] { return k.indices.size(); }));
  EXPECT_EQ(s.session->warm_ups(), 1);
  ASSERT_GE(end.frames, 2u);
  EXPECT_TRUE(k.cold.front()) << "the warm-up's fit was reset: the first frame starts cold";
  for (std::size_t i = 1; i < k.cold.size(); ++i) EXPECT_FALSE(k.cold[i]) << "frame " << i;

  SimulatedSetup cold(0.5, false);
  cold.session->start();
  EXPECT_EQ(cold.session->warm_ups(), 0);
  cold.session->stop();
}

TEST(Session, ASinkThatThrowsStopsTheSessionCleanly) {
  SimulatedSetup s(3.0);
  TracingSink before, after;
  FunctionSink thrower([](const FrameEvent& e) {
    if (e.index == 3) throw std::runtime_error("sink failed at frame 3");
  });
  s.session->add_sink(before);
  s.session->add_sink(thrower);
  s.session->add_sink(after);
  EXPECT_THROW(
      {
        try {
          s.session->run();
        } catch (const std::runtime_error& e) {
          EXPECT_STREQ(e.what(), "sink failed at frame 3");
          throw;
        }
      },
      std::runtime_error);
  EXPECT_FALSE(s.session->running());
  EXPECT_FALSE(s.session->servo().running()) << "the servo thread is joined";
  EXPECT_FALSE(s.rig->device().status().open) << "the device is closed (in its safe state)";
  EXPECT_EQ(before.indices.size(), 4u);
  EXPECT_EQ(after.indices.size(), 3u) << "sinks after the failing one do not see its frame";
  EXPECT_EQ(before.calls.find('e'), std::string::npos) << "on_end only for a run that ended";
}

// The comparison left to the output thread (SessionParams::defer_compare, AsyncSinks::compare):
// fitted on every frame, pictured (both composites) on every compare_every-th, and the same fit a
// comparison pipeline on the frame's own inputs makes here afterwards (the one the frame thread
// used to make), to the last bit.
TEST(Session, ADeferredComparisonIsFittedOnTheOutputThreadAsTheFrameThreadWould) {
  constexpr int kEvery = 3;
  SimulatedSetup s(kBackstopS, true, [](SessionParams& sp) {
    sp.compare = true;
    sp.defer_compare = true;
    sp.compare_every = kEvery;
    sp.pipeline.other_composite = false;
  });
  ASSERT_NE(s.session->comparison_params(), nullptr);
  EXPECT_NE(s.session->comparison_params()->registration.silhouette_term,
            s.params.pipeline.registration.silhouette_term);
  struct Seen {
    std::uint64_t index = 0;
    cv::Mat bgr;
    device::FingertipSample measured;
    SceneSnapshot scene;
    vision::ChromaKeyResult key;
    std::array<hand::HandModel, 2> models;
    bool compared = false, compared_other = false, main_other = false;
    std::array<hand::HandParams, 2> compared_hands{};
    std::thread::id thread;
  };
  std::vector<Seen> seen;
  FunctionSink keep([&](const FrameEvent& e) {
    Seen k;
    k.index = e.index;
    e.bgr->copyTo(k.bgr);
    k.measured = *e.measured;
    k.scene = *e.scene;
    e.result->key.alpha.copyTo(k.key.alpha);
    e.result->key.silhouette.copyTo(k.key.silhouette);
    e.result->key.foreground.copyTo(k.key.foreground);
    k.models = e.result->models;
    k.main_other = !e.result->other_alpha.empty();
    k.compared = e.compared != nullptr;
    if (e.compared != nullptr) {
      k.compared_hands = e.compared->hands;
      k.compared_other = !e.compared->other_alpha.empty() && !e.compared->composite.empty();
    }
    k.thread = std::this_thread::get_id();
    seen.push_back(std::move(k));
  });
  AsyncSinks off_path({&keep}, 3, 0);
  off_path.compare(s.camera, s.models, s.params.pipeline);
  off_path.compose_others(s.params.pipeline.compositor);
  s.session->add_sink(off_path);
  // Counted where the frame thread hands frames to the output thread (the sink `keep` runs
  // behind it): frames 0, 3 and 6 are the pictured ones.
  std::size_t handed = 0;
  FunctionSink count([&](const FrameEvent&) { ++handed; });
  s.session->add_sink(count);
  const SessionSummary end = s.session->run(after_frames(7, [&] { return handed; }));
  ASSERT_GE(end.frames, 4u);
  ASSERT_EQ(seen.size(), end.frames);

  auto replay = pipeline::FramePipeline::create(*s.context, s.camera, s.models,
                                                pipeline::comparison_params(s.params.pipeline))
                    .value();
  pipeline::FrameResult r;
  int compared = 0;
  for (const Seen& k : seen) {
    EXPECT_NE(k.thread, std::this_thread::get_id());
    EXPECT_TRUE(k.main_other) << "frame " << k.index << ": the other composite, made off the frame thread";
    const bool picture = k.index % kEvery == 0;
    EXPECT_EQ(k.compared, picture) << "frame " << k.index;
    replay->use_model_sizes(k.models);
    ASSERT_TRUE(replay->process(k.bgr, k.measured, k.scene, &r, !picture, &k.key).ok());
    if (!picture) continue;
    ++compared;
    EXPECT_TRUE(k.compared_other) << "frame " << k.index;
    for (int h = 0; h < 2; ++h)
      EXPECT_EQ((k.compared_hands[h].q - r.hands[h].q).norm(), 0.0) << "frame " << k.index << " hand " << h;
  }
  EXPECT_GE(compared, 2);
}

TEST(FrameStatsSink, HistoryNeverExceedsItsCapacityAndMeansCoverTheWholeRun) {
  SimulatedSetup s(kBackstopS);
  FrameStatsSink stats(2);  // a capacity of 2: the run's 4 frames overflow it
  TracingSink k;
  s.session->add_sink(stats);
  s.session->add_sink(k);
  const SessionSummary end = s.session->run(after_frames(4, [&] { return k.indices.size(); }));
  ASSERT_GT(end.frames, 2u);
  EXPECT_EQ(stats.history().size(), 2u);
  EXPECT_EQ(stats.history().pushed(), end.frames);
  for (std::size_t i = 0; i < 2; ++i)  // the newest two, oldest first
    EXPECT_DOUBLE_EQ(stats.history()[i].t_s, k.times[k.times.size() - 2 + i]);
  EXPECT_GT(stats.iou_mean(), 0.0);
  EXPECT_LE(stats.iou_mean(), 1.0);
}

TEST(HistoryRing, KeepsTheNewestValuesOldestFirst) {
  HistoryRing<int> r(3);
  EXPECT_TRUE(r.empty());
  for (int v = 1; v <= 7; ++v) {
    r.push(v);
    EXPECT_LE(r.size(), 3u);
    EXPECT_EQ(r.back(), v);
  }
  EXPECT_EQ(r.pushed(), 7u);
  EXPECT_EQ(r[0], 5);
  EXPECT_EQ(r[1], 6);
  EXPECT_EQ(r[2], 7);
  EXPECT_THROW(HistoryRing<int>(0), SpidarError);
}

}  // namespace
}  // namespace spidar::session
