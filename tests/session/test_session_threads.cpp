// The demo's threads together, for ThreadSanitizer (the tsan preset builds and runs this
// executable): the simulated device's servo thread, the physics thread, the camera thread, the
// frame thread, the size estimator's thread and AsyncSinks' output thread, which scores the
// truth, fits the comparison and makes the paper's composite on results the frame thread holds
// for it. The run ends after a number of frames, not after a time: under a sanitizer a frame
// takes ten times as long, and nothing here depends on how long.
#include <gtest/gtest.h>

#include <opencv2/core/utility.hpp>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <thread>

#include "after_frames.hpp"
#include "simulated_setup.hpp"
#include "spidar/render/context.hpp"
#include "spidar/session/async_sinks.hpp"
#include "spidar/session/frame_stats.hpp"
#include "spidar/session/truth_scorer.hpp"

namespace spidar::session {
namespace {

TEST(SessionThreads, TheDemosThreadsHandOverEveryFrameAndItsHeldResults) {
  // The demo renders in the drawing thread (no llvmpipe workers), as its main does. OpenCV's own
  // worker threads (TBB's, which TSan cannot see synchronise) are left out: every image operation
  // runs on the thread that calls it, so what TSan checks is how our threads hand images over.
  render::render_in_drawing_thread();
  cv::setNumThreads(0);
  constexpr int kFrames = 6;
  constexpr int kEvery = 2;
  SimulatedSetup s(600.0, true, [](SessionParams& sp) {
    sp.pipeline.registration.silhouette_term = true;
    sp.pipeline.personalise_shape = true;  // the size estimator's own thread
    sp.compare = true;
    sp.defer_compare = true;
    sp.compare_every = kEvery;
    sp.pipeline.other_composite = false;
  });
  TruthScorer scorer(s.camera, s.user, s.params.pipeline);
  std::atomic<int> output_frames{0};
  std::atomic<int> pictures{0};
  std::thread::id output_thread;
  FunctionSink count([&](const FrameEvent& e) {
    output_thread = std::this_thread::get_id();
    if (e.compared != nullptr && !e.compared->composite.empty() && !e.result->other_alpha.empty())
      pictures.fetch_add(1);
    output_frames.fetch_add(1);
  });
  // A slow reader after the others: the frame thread fills the free slots and waits for this one,
  // so a slot or a held result handed back before its sinks are done would be written while read.
  double checksum = 0;
  FunctionSink slow([&](const FrameEvent& e) {
    std::this_thread::sleep_for(std::chrono::milliseconds(40));
    checksum += e.measured->p_W[1][0] + e.result->hands[0].q.sum() + e.scene->t_s;
  });
  AsyncSinks off_path({&scorer, &count, &slow}, 2, 0);
  off_path.compare(s.camera, s.models, s.params.pipeline);
  off_path.compose_others(s.params.pipeline.compositor);
  FrameStatsSink stats(4);  // on the frame thread, as the GUI's view model
  s.session->add_sink(stats);
  s.session->add_sink(off_path);

  std::atomic<int> frame_thread_frames{0};
  FunctionSink frame_side([&](const FrameEvent&) { frame_thread_frames.fetch_add(1); });
  s.session->add_sink(frame_side);
  const SessionSummary end =
      s.session->run(testing::after_frames(static_cast<std::size_t>(kFrames), [&] { return frame_thread_frames.load(); }));

  EXPECT_EQ(end.ended_by, "enough frames");
  EXPECT_TRUE(end.camera_error.empty()) << end.camera_error;
  ASSERT_GE(end.frames, static_cast<std::uint64_t>(kFrames));
  EXPECT_EQ(output_frames.load(), static_cast<int>(end.frames)) << "the output thread saw every frame";
  EXPECT_NE(output_thread, std::this_thread::get_id());
  ASSERT_EQ(scorer.trace().frames.size(), end.frames);
  int compared = 0;
  for (const TruthFrame& f : scorer.trace().frames) {
    compared += f.compared ? 1 : 0;
    EXPECT_GT(f.truth[0].iou, 0.0);
  }
  EXPECT_GE(compared, kFrames / kEvery);
  EXPECT_EQ(pictures.load(), compared) << "each compared frame has both composites";
  EXPECT_TRUE(std::isfinite(checksum));
  std::printf("frames %llu, the frame thread waited for a free slot %llu times\n",
              static_cast<unsigned long long>(end.frames), static_cast<unsigned long long>(off_path.waits()));
  EXPECT_FALSE(s.session->running());
  EXPECT_FALSE(s.session->servo().running());
}

}  // namespace
}  // namespace spidar::session
