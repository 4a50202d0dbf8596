// AsyncSinks: the sinks run on one output thread, in order, on deep copies of each event (or on the
// main result itself where the event shares it); a slow sink makes the frame thread wait (no frame
// is skipped); a sink's exception comes back.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <limits>
#include <stdexcept>
#include <thread>

#include "spidar/core/recycling_pool.hpp"
#include "spidar/session/async_sinks.hpp"

namespace spidar::session {
namespace {

/// Records what it saw: the thread of each call, the frame index, a pixel of each image.
class Recorder final : public FrameSink {
 public:
  void on_start() override { start_thread = std::this_thread::get_id(); }
  void on_frame(const FrameEvent& e) override {
    frame_threads.push_back(std::this_thread::get_id());
    indices.push_back(e.index);
    bgr_pixel.push_back(e.bgr->at<cv::Vec3b>(1, 2)[0]);
    composite_pixel.push_back(e.result->composite.at<cv::Vec3b>(0, 0)[1]);
    alpha_pixel.push_back(e.result->composite_alpha.at<float>(0, 0));
    compared.push_back(e.compared != nullptr ? e.compared->hands[1].q[3] : -1.0);
    fingertip_x.push_back(e.measured->p_W[2][0]);
    truth_pixel.push_back(e.filmed != nullptr ? e.filmed->frame.hand_only.at<std::uint8_t>(0, 1) : 0);
    if (delay_ms > 0) std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms));
    if (throw_at >= 0 && e.index == static_cast<std::uint64_t>(throw_at)) throw std::runtime_error("sink failed");
  }
  void on_end(const SessionSummary& s) override {
    end_thread = std::this_thread::get_id();
    ended_by = s.ended_by;
  }
  std::thread::id start_thread, end_thread;
  std::vector<std::thread::id> frame_threads;
  std::vector<std::uint64_t> indices;
  std::vector<int> bgr_pixel, composite_pixel, truth_pixel;
  std::vector<float> alpha_pixel;
  std::vector<double> compared, fingertip_x;
  std::string ended_by;
  int delay_ms = 0;
  int throw_at = -1;
};

/// One frame's worth of buffers, overwritten for every frame as the session's are.
struct Buffers {
  cv::Mat bgr{4, 5, CV_8UC3, cv::Scalar::all(0)};
  device::FingertipSample measured;
  SceneSnapshot scene;
  pipeline::FrameResult result, compared;
  sim::FilmedFrame filmed;
  Buffers() {
    result.composite = cv::Mat(4, 5, CV_8UC3, cv::Scalar::all(0));
    result.composite_alpha = cv::Mat(4, 5, CV_32FC1, cv::Scalar::all(0));
    filmed.frame.hand_only = cv::Mat(4, 5, CV_8UC1, cv::Scalar::all(0));
  }
  /// Writes frame k's values into the shared buffers and returns the event pointing at them.
  FrameEvent event(int k, bool with_compared) {
    bgr.setTo(cv::Scalar::all(k));
    result.composite.setTo(cv::Scalar::all(2 * k));
    result.composite_alpha.setTo(0.01f * static_cast<float>(k));
    compared.hands[1].q[3] = 10.0 * k;
    measured.p_W[2][0] = 0.5 * k;
    filmed.frame.hand_only.setTo(3 * k);
    FrameEvent e;
    e.index = static_cast<std::uint64_t>(k);
    e.bgr = &bgr;
    e.measured = &measured;
    e.scene = &scene;
    e.result = &result;
    e.compared = with_compared ? &compared : nullptr;
    e.filmed = &filmed;
    return e;
  }
};

TEST(AsyncSinks, EverySinkSeesEveryFrameInOrderOnOneOutputThreadWithItsOwnCopies) {
  Recorder a, b;
  b.delay_ms = 3;  // slower than the frames come: the frame thread must wait, not skip
  Buffers buf;
  const int n = 12;
  {
    AsyncSinks sinks({&a, &b}, 2);
    sinks.on_start();
    for (int k = 0; k < n; ++k) sinks.on_frame(buf.event(k, k % 3 == 0));
    SessionSummary s;
    s.ended_by = "completed";
    sinks.on_end(s);
  }
  for (const Recorder* r : {&a, &b}) {
    ASSERT_EQ(r->indices.size(), static_cast<std::size_t>(n));
    EXPECT_NE(r->start_thread, std::this_thread::get_id());
    EXPECT_EQ(r->end_thread, r->start_thread);
    EXPECT_EQ(r->ended_by, "completed");
    for (int k = 0; k < n; ++k) {
      const auto i = static_cast<std::size_t>(k);
      EXPECT_EQ(r->frame_threads[i], r->start_thread);
      EXPECT_EQ(r->indices[i], static_cast<std::uint64_t>(k));
      // The buffers were overwritten by later frames before the sinks ran: copies, not views.
      EXPECT_EQ(r->bgr_pixel[i], k);
      EXPECT_EQ(r->composite_pixel[i], 2 * k);
      EXPECT_FLOAT_EQ(r->alpha_pixel[i], 0.01f * static_cast<float>(k));
      EXPECT_DOUBLE_EQ(r->compared[i], k % 3 == 0 ? 10.0 * k : -1.0);
      EXPECT_DOUBLE_EQ(r->fingertip_x[i], 0.5 * k);
      EXPECT_EQ(r->truth_pixel[i], 3 * k);
    }
  }
}

// The session's way: each frame's result and filmed frame taken from pools and shared
// (FrameEvent::result_hold, filmed_hold; the camera image a header on the filmed frame's). The sinks
// see the very objects, not copies; while they hold them the pools never hand them out again, so
// frames filled later cannot overwrite them; and once they are done they go back to their pools.
TEST(AsyncSinks, SharedResultsAndFilmedFramesAreHeldNotCopiedAndGoBackToTheirPools) {
  class Addresses final : public FrameSink {
   public:
    void on_frame(const FrameEvent& e) override {
      seen.push_back(e.result);
      seen_filmed.push_back(e.filmed);
      seen_image.push_back(e.bgr->data);
      composite_pixel.push_back(e.result->composite.at<cv::Vec3b>(0, 0)[1]);
      bgr_pixel.push_back(e.bgr->at<cv::Vec3b>(1, 2)[0]);
      truth_pixel.push_back(e.filmed->frame.hand_only.at<std::uint8_t>(0, 1));
      std::this_thread::sleep_for(std::chrono::milliseconds(2));  // slower than the frames
    }
    std::vector<const pipeline::FrameResult*> seen;
    std::vector<const sim::FilmedFrame*> seen_filmed;
    std::vector<const std::uint8_t*> seen_image;
    std::vector<int> composite_pixel, bgr_pixel, truth_pixel;
  } sink;
  core::RecyclingPool<pipeline::FrameResult> pool;
  core::RecyclingPool<sim::FilmedFrame> films;  // as sim::CameraThread's
  Buffers buf;
  const int n = 20;
  std::vector<const pipeline::FrameResult*> handed;
  std::vector<const sim::FilmedFrame*> handed_filmed;
  std::vector<const std::uint8_t*> handed_image;
  {
    AsyncSinks sinks({&sink}, 3);
    sinks.on_start();
    for (int k = 0; k < n; ++k) {
      auto result = pool.take();
      result->composite.create(4, 5, CV_8UC3);
      result->composite.setTo(cv::Scalar::all(2 * k));
      auto filmed = films.take();
      filmed->frame.bgr.create(4, 5, CV_8UC3);
      filmed->frame.bgr.setTo(cv::Scalar::all(k));
      filmed->frame.hand_only.create(4, 5, CV_8UC1);
      filmed->frame.hand_only.setTo(3 * k);
      const cv::Mat image = filmed->frame.bgr;  // the session's image: a header on the filmed frame's
      FrameEvent e = buf.event(k, false);
      e.result = result.get();
      e.result_hold = result;
      e.bgr = &image;
      e.filmed = filmed.get();
      e.filmed_hold = filmed;
      handed.push_back(result.get());
      handed_filmed.push_back(filmed.get());
      handed_image.push_back(image.data);
      sinks.on_frame(e);
    }
    SessionSummary s;
    sinks.on_end(s);
  }
  ASSERT_EQ(sink.seen.size(), static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    const auto i = static_cast<std::size_t>(k);
    EXPECT_EQ(sink.seen[i], handed[i]);                // the objects themselves, not copies
    EXPECT_EQ(sink.seen_filmed[i], handed_filmed[i]);
    EXPECT_EQ(sink.seen_image[i], handed_image[i]);
    EXPECT_EQ(sink.composite_pixel[i], 2 * k);         // not overwritten by a later frame
    EXPECT_EQ(sink.bgr_pixel[i], k);
    EXPECT_EQ(sink.truth_pixel[i], 3 * k);
  }
  // Recycled: no more objects than the slots, the one being filled and the one just let go.
  EXPECT_LE(pool.created(), 5u);
  EXPECT_LE(films.created(), 5u);
  EXPECT_EQ(pool.free(), pool.created());  // every one back once the sinks are done
  EXPECT_EQ(films.free(), films.created());
}

TEST(AsyncSinks, ASinkThatThrowsStopsTheFramesAndTheErrorComesBackToTheFrameThread) {
  Recorder a, after;
  a.throw_at = 2;
  Buffers buf;
  AsyncSinks sinks({&a, &after}, 1);
  sinks.on_start();
  bool thrown = false;
  for (int k = 0; k < 20 && !thrown; ++k) {
    try {
      sinks.on_frame(buf.event(k, false));
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "sink failed");
      thrown = true;
    }
  }
  if (!thrown) {  // the last frames were queued before the failure was known: it comes at the end
    EXPECT_THROW(sinks.on_end(SessionSummary{}), std::runtime_error);
  } else {
    sinks.on_end(SessionSummary{});
  }
  EXPECT_EQ(a.indices.size(), 3u);      // frames 0, 1, 2: none after the failure
  EXPECT_EQ(after.indices.size(), 2u);  // the sink after it never saw frame 2
  EXPECT_TRUE(a.ended_by.empty());      // no on_end after a failure
}

TEST(AsyncSinks, AComparisonLeftPendingWithNobodyToMakeItIsAnError) {
  Recorder a;
  Buffers buf;
  AsyncSinks sinks({&a}, 1);
  sinks.on_start();
  FrameEvent e = buf.event(0, false);
  e.compare_pending = PendingComparison::kFit;  // the session deferred it, but no compare()
  sinks.on_frame(e);
  try {
    sinks.on_end(SessionSummary{});
    ADD_FAILURE() << "no error";
  } catch (const SpidarError& err) {
    EXPECT_NE(std::string(err.what()).find("AsyncSinks::compare"), std::string::npos) << err.what();
  }
  EXPECT_TRUE(a.indices.empty());  // the sinks never saw a frame without its comparison
}

// compose_others: the other compositor's picture (here the paper's: the real image exactly where
// the virtual hand is in front of the scene) is made on the output thread for a held result and a
// copied comparison, the held result itself left as the frame thread made it.
TEST(AsyncSinks, TheOtherCompositeIsMadeOnTheOutputThreadWithoutTouchingTheHeldResult) {
  class Others final : public FrameSink {
   public:
    void on_frame(const FrameEvent& e) override {
      ASSERT_NE(e.result, nullptr);
      ASSERT_NE(e.compared, nullptr);
      results.push_back(e.result);
      other_alpha.push_back(e.result->other_alpha.clone());
      other.push_back(e.result->other.clone());
      compared_alpha.push_back(e.compared->other_alpha.clone());
      composite_pixel.push_back(e.result->composite.at<cv::Vec3b>(0, 0)[1]);
    }
    std::vector<const pipeline::FrameResult*> results;
    std::vector<cv::Mat> other_alpha, other, compared_alpha;
    std::vector<int> composite_pixel;
  } sink;
  const cv::Size size(5, 4);
  // Frame k: a virtual hand at 0.4 m over columns x < k + 1, the scene at 0.5 m everywhere but
  // row 0 (0.3 m, in front of the hand); the real image grey 200, the virtual one grey 50.
  auto fill = [&](pipeline::FrameResult& r, int k) {
    r.virt.colour.create(size, CV_8UC3);
    r.virt.colour.setTo(cv::Scalar::all(50));
    r.virt.depth.create(size, CV_32FC1);
    r.virt.depth.setTo(0.5f);
    r.virt.depth.row(0).setTo(0.3f);
    r.virt.hand_depth.create(size, CV_32FC1);
    r.virt.hand_depth.setTo(std::numeric_limits<float>::infinity());
    r.virt.hand_depth.colRange(0, k + 1).setTo(0.4f);
    r.virt.hand_id.create(size, CV_8UC1);
    r.virt.hand_id.setTo(0);
    r.virt.hand_box.reset();
    r.key.alpha.create(size, CV_32FC1);
    r.key.alpha.setTo(1.f);
    r.composite.create(size, CV_8UC3);
    r.composite.setTo(cv::Scalar::all(2 * k));
  };
  core::RecyclingPool<pipeline::FrameResult> pool;
  Buffers buf;
  cv::Mat image(size, CV_8UC3, cv::Scalar::all(200));
  const int n = 4;
  std::vector<const pipeline::FrameResult*> handed;
  {
    AsyncSinks sinks({&sink}, 2);
    render::CompositorParams main;
    main.mode = render::CompositeMode::kDepth;
    sinks.compose_others(main);
    sinks.on_start();
    for (int k = 0; k < n; ++k) {
      auto result = pool.take();
      fill(*result, k);
      fill(buf.compared, k);
      FrameEvent e = buf.event(k, true);
      e.bgr = &image;
      e.result = result.get();
      e.result_hold = result;
      handed.push_back(result.get());
      sinks.on_frame(e);
    }
    sinks.on_end(SessionSummary{});
    EXPECT_THROW(sinks.compose_others(main), std::logic_error);  // after on_start
  }
  ASSERT_EQ(sink.other_alpha.size(), static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    const auto i = static_cast<std::size_t>(k);
    EXPECT_NE(sink.results[i], handed[i]);  // a view with the other composite, not the held one
    EXPECT_EQ(sink.composite_pixel[i], 2 * k);
    ASSERT_EQ(sink.other_alpha[i].size(), size);
    ASSERT_EQ(sink.compared_alpha[i].size(), size);
    for (int y = 0; y < size.height; ++y)
      for (int x = 0; x < size.width; ++x) {
        const bool real = y > 0 && x < k + 1;  // the hand in front of the scene
        EXPECT_EQ(sink.other_alpha[i].at<float>(y, x), real ? 1.f : 0.f) << k << " " << x << "," << y;
        EXPECT_EQ(sink.compared_alpha[i].at<float>(y, x), real ? 1.f : 0.f) << k << " " << x << "," << y;
        EXPECT_EQ(sink.other[i].at<cv::Vec3b>(y, x)[0], real ? 200 : 50) << k << " " << x << "," << y;
      }
  }
  for (const auto* r : handed) EXPECT_TRUE(r->other.empty());  // the held results untouched
  EXPECT_EQ(pool.free(), pool.created());
}

TEST(AsyncSinks, AnOnStartThatThrowsIsReThrownByOnStart) {
  struct Failing final : FrameSink {
    void on_start() override { throw std::runtime_error("no GL"); }
    void on_frame(const FrameEvent&) override {}
  } failing;
  AsyncSinks sinks({&failing});
  EXPECT_THROW(sinks.on_start(), std::runtime_error);
}

}  // namespace
}  // namespace spidar::session
