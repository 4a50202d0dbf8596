// The simulated camera's thread (sim/camera_thread.hpp): every exposure is either filmed or
// counted as skipped, so a frame's index gap is what the report calls dropped and skipped (the
// demo's frames.csv `dropped_before` column sums to at most the report's figures).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <map>
#include <memory>
#include <mutex>
#include <span>
#include <thread>
#include <vector>

#include <opencv2/core.hpp>

#include "spidar/core/clock.hpp"
#include "spidar/hand/kinematics.hpp"
#include "spidar/sim/camera_thread.hpp"
#include "spidar/sim/rubiks_task.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::sim {
namespace {

/// What every camera here films: the default hands at the Rubik's task's nominal poses, on the
/// default rig camera.
struct Filmed {
  std::array<hand::HandModel, 2> truth{hand::default_hand_model(hand::Side::kLeft),
                                       hand::default_hand_model(hand::Side::kRight)};
  RubiksTask task{{}};

  /// The script's nominal fingertips of both hands at script time t (what the simulated device's
  /// ground truth gives a camera thread), into out[0..7].
  void caps(double t, std::span<Vec3> out) const {
    for (int h = 0; h < 2; ++h) {
      const hand::HandModel& m = truth[static_cast<std::size_t>(h)];
      const hand::HandPoints pts = hand::forward_kinematics(m, task.nominal(t, m.side));
      for (int f = 0; f < hand::kFingertipCount; ++f) out[static_cast<std::size_t>(4 * h + f)] = pts.p_W_fingertip[f];
    }
  }
  /// The fingertips at exposure time t_ns of a clock started at t0_ns: the script from 1 s on,
  /// hands in view and moving.
  void caps_at(std::int64_t t0_ns, std::int64_t t_ns, std::span<Vec3> out) const {
    caps(1.0 + core::ns_to_s(t_ns - t0_ns), out);
  }
  /// A ground truth that always has them, for a clock started at *t0_ns (read at each exposure:
  /// it may be set after the camera is prepared).
  TruthAt nominal_from(const std::atomic<std::int64_t>* t0_ns) const {
    return [this, t0_ns](std::int64_t t_ns, std::span<Vec3> out) {
      caps_at(t0_ns->load(), t_ns, out);
      return Truth::kExact;
    };
  }
  Result<std::unique_ptr<CameraThread>> start(TruthAt truth_at, const CameraThreadParams& params) const {
    return CameraThread::start(vision::default_rig_camera(), truth, {}, task, std::move(truth_at), params);
  }
  Result<std::unique_ptr<CameraThread>> prepare(TruthAt truth_at, const CameraThreadParams& params) const {
    return CameraThread::prepare(vision::default_rig_camera(), truth, {}, task, std::move(truth_at), params);
  }
};

// The ground truth has no fingertips for the first 0.2 s (as when the device's first samples
// come late on a busy machine): those exposures are skipped, not lost from the counts.
TEST(CameraThread, ExposuresWithoutTruthCountAsSkipped) {
  const Filmed filmed;
  CameraThreadParams params;
  params.fps = 30;
  params.t0_ns = core::monotonic_ns();
  const std::int64_t t0 = params.t0_ns;
  std::atomic<int> refused{0};
  TruthAt truth_at = [&](std::int64_t t_ns, std::span<Vec3> out) {
    if (t_ns < t0 + 200'000'000) {
      ++refused;
      return Truth::kNone;
    }
    filmed.caps(core::ns_to_s(t_ns - t0), out);
    return Truth::kExact;
  };
  auto thread = filmed.start(truth_at, params);
  ASSERT_TRUE(thread.ok()) << thread.error().message;
  CameraThread& cam = *thread.value();
  std::uint64_t last_index = 0;
  int taken = 0;
  for (int i = 0; i < 2000 && taken < 3; ++i) {  // waits for frames, not for a time
    if (cam.take()) {
      last_index = cam.frame().index;
      ++taken;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  cam.stop();
  ASSERT_EQ(taken, 3) << cam.error();
  EXPECT_GE(refused.load(), 1);
  // The exposures before the first truth (6 at 30 fps in 0.2 s) were skipped, whatever the load.
  EXPECT_GE(cam.skipped(), 6u);
  EXPECT_GE(last_index, 6u);
  // Every index before the last frame's was filmed or skipped.
  EXPECT_LE(last_index + 1, cam.filmed() + cam.skipped());
}

// The device's first sample comes just after the session's clock starts (t0): the first exposure
// is first_exposure_ns later, so it has its ground truth (at t0 itself it had none and every run
// dropped its first frame). A readout of a second keeps a loaded machine from making it late.
TEST(CameraThread, TheFirstExposureComesAfterTheDevicesFirstSample) {
  const Filmed filmed;
  for (const std::int64_t phase : {std::int64_t{5'000'000}, std::int64_t{0}}) {
    CameraThreadParams params;
    params.fps = 30;
    params.readout_ns = 1'000'000'000;
    params.first_exposure_ns = phase;
    params.t0_ns = core::monotonic_ns() + 100'000'000;
    const std::int64_t t0 = params.t0_ns;
    std::mutex m;
    std::vector<std::pair<std::int64_t, bool>> asked;  // exposure time, truth given
    TruthAt truth_at = [&](std::int64_t t_ns, std::span<Vec3> out) {
      const bool have = t_ns > t0;  // the device's first sample is just after t0
      if (have) filmed.caps_at(t0, t_ns, out);
      const std::lock_guard lock(m);
      asked.emplace_back(t_ns, have);
      return have ? Truth::kExact : Truth::kNone;
    };
    auto thread = filmed.start(truth_at, params);
    ASSERT_TRUE(thread.ok()) << thread.error().message;
    CameraThread& cam = *thread.value();
    ASSERT_TRUE(cam.wait_for_frame(core::monotonic_ns() + 60'000'000'000)) << cam.error();
    ASSERT_TRUE(cam.take());
    cam.stop();
    const std::lock_guard lock(m);
    ASSERT_FALSE(asked.empty());
    EXPECT_EQ(asked.front().first, t0 + phase);
    EXPECT_EQ(asked.front().second, phase > 0) << "phase " << phase;
    EXPECT_EQ(cam.frame().index, phase > 0 ? 0u : 1u);
  }
  CameraThreadParams bad;
  bad.first_exposure_ns = -1;
  TruthAt any = [](std::int64_t, std::span<Vec3>) { return Truth::kNone; };
  auto refused = filmed.prepare(any, bad);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("first_exposure_ns"), std::string::npos) << refused.error().message;
  bad = {};
  bad.warm_frames = 65;
  refused = filmed.prepare(any, bad);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("warm_frames"), std::string::npos) << refused.error().message;
}

// A prepared camera (CameraThread::prepare: its GL context made and one frame filmed and thrown
// away before the session's clock starts) films nothing until begin(); the exposures then start
// at the t0 begin() gives, however long ago prepare() was, and none was skipped for the time
// the preparation took. Stopping a camera that never began ends its thread.
TEST(CameraThread, APreparedCameraFilmsFromItsBeginOnly) {
  const Filmed filmed;
  std::atomic<std::int64_t> t0{0};
  std::atomic<int> asked_before_begin{0};
  TruthAt truth_at = [&](std::int64_t t_ns, std::span<Vec3> out) {
    if (t0.load() == 0) ++asked_before_begin;
    filmed.caps_at(t0.load(), t_ns, out);
    return Truth::kExact;
  };
  CameraThreadParams params;
  params.fps = 30;
  {
    auto never = filmed.prepare(truth_at, params);
    ASSERT_TRUE(never.ok()) << never.error().message;
    never.value()->stop();  // returns: the thread ended without beginning
    EXPECT_EQ(never.value()->filmed(), 0u);
    EXPECT_EQ(never.value()->skipped(), 0u);
  }
  auto thread = filmed.prepare(truth_at, params);
  ASSERT_TRUE(thread.ok()) << thread.error().message;
  CameraThread& cam = *thread.value();
  std::this_thread::sleep_for(std::chrono::milliseconds(150));  // longer than 4 frame periods
  EXPECT_FALSE(cam.take());
  EXPECT_EQ(cam.filmed(), 0u);
  EXPECT_EQ(cam.skipped(), 0u);
  t0 = core::monotonic_ns();
  cam.begin(t0.load());
  int taken = 0;
  for (int i = 0; i < 2000 && taken == 0; ++i) {  // waits for a frame, not for a time
    if (cam.take()) ++taken;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  cam.stop();
  ASSERT_EQ(taken, 1) << cam.error();
  EXPECT_EQ(asked_before_begin.load(), 0);
  // Its first exposure is first_exposure_ns after t0, or a whole number of periods after that (if
  // the taker was late).
  const std::int64_t period_ns = static_cast<std::int64_t>(1e9 / params.fps);
  const FilmedFrame& f = cam.frame();
  EXPECT_EQ(f.t_exposure_ns, t0.load() + params.first_exposure_ns + static_cast<std::int64_t>(f.index) * period_ns);
  EXPECT_LE(f.index + 1, cam.filmed() + cam.skipped());
}

// The posing and filming run during the sensor's readout, not after it: the truth is asked for
// from the exposure on (an exact source is used at once), and no frame is published before its
// readout has ended (readout_ns after the exposure), however fast the filming. A readout of a second (longer than any stall of a loaded machine, and than the frame
// period: the frames overlap) makes both visible at any speed; a negative one is refused.
TEST(CameraThread, FilmsDuringTheReadoutAndPublishesAfterIt) {
  const Filmed filmed;
  CameraThreadParams params;
  params.fps = 4;
  params.readout_ns = 1'000'000'000;
  params.truth_wait_ns = 1'000'000;
  params.t0_ns = core::monotonic_ns() + 200'000'000;  // after the thread's start and warm-up frame
  const std::int64_t t0 = params.t0_ns;
  std::vector<std::int64_t> asked_after;  // monotonic time of each truth request minus its exposure
  std::mutex m;
  TruthAt truth_at = [&](std::int64_t t_ns, std::span<Vec3> out) {
    const std::int64_t now = core::monotonic_ns();
    {
      const std::lock_guard lock(m);
      asked_after.push_back(now - t_ns);
    }
    filmed.caps_at(t0, t_ns, out);
    return Truth::kExact;
  };
  auto thread = filmed.start(truth_at, params);
  ASSERT_TRUE(thread.ok()) << thread.error().message;
  CameraThread& cam = *thread.value();
  std::vector<std::int64_t> published_after;  // when take() first saw a frame, minus its exposure
  for (int i = 0; i < 4000 && published_after.size() < 3; ++i) {  // waits for frames, not for a time
    if (cam.take()) published_after.push_back(core::monotonic_ns() - cam.frame().t_exposure_ns);
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  cam.stop();
  ASSERT_EQ(published_after.size(), 3u) << cam.error();
  for (std::int64_t d : published_after) EXPECT_GE(d, params.readout_ns) << "published before its readout";
  const std::lock_guard lock(m);
  ASSERT_GE(asked_after.size(), 3u);
  for (std::int64_t d : asked_after) EXPECT_GE(d, 0) << "truth asked before the exposure";
  // The truth was asked for before the readout ended (a frame filmed after it would add the
  // filming to the latency): at least one of them, whatever the machine's load.
  EXPECT_LT(*std::min_element(asked_after.begin(), asked_after.end()), params.readout_ns);

  CameraThreadParams bad = params;
  bad.readout_ns = -1;
  auto refused = filmed.prepare(truth_at, bad);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("readout_ns"), std::string::npos) << refused.error().message;
}

// The camera waits for the exposure's exact ground truth (the device's sample after it), asking
// every truth_poll_ns, and films with the newest sample held only when truth_wait_ns has passed
// without it: a source exact from each exposure's second ask on is filmed exact with a wait of
// 10 ms; one that only ever holds is filmed held, after the wait.
TEST(CameraThread, WaitsForTheExposuresExactTruthAndHoldsOnlyPastTheWait) {
  const Filmed filmed;
  for (const bool ever_exact : {true, false}) {
    SCOPED_TRACE(ever_exact ? "exact 3 ms after the exposure" : "held only");
    CameraThreadParams params;
    params.fps = 10;
    params.readout_ns = 20'000'000;
    params.truth_wait_ns = 10'000'000;
    params.truth_poll_ns = 200'000;
    std::atomic<std::int64_t> t0{0};
    std::mutex m;
    struct Ask {
      std::int64_t exposure, after;
      Truth had;
    };
    std::vector<Ask> asks;
    std::map<std::int64_t, int> asked;  // per exposure, how often
    // Exact from an exposure's second ask on (by count, not by time: a camera woken late on every
    // exposure must still see a held answer first).
    TruthAt truth_at = [&](std::int64_t t_ns, std::span<Vec3> out) {
      const std::int64_t after = core::monotonic_ns() - t_ns;
      filmed.caps_at(t0.load(), t_ns, out);
      const std::lock_guard lock(m);
      const Truth had = ever_exact && ++asked[t_ns] >= 2 ? Truth::kExact : Truth::kHeld;
      asks.push_back({t_ns, after, had});
      return had;
    };
    auto thread = filmed.prepare(truth_at, params);  // its GL context and warm-up done
    ASSERT_TRUE(thread.ok()) << thread.error().message;
    CameraThread& cam = *thread.value();
    t0 = core::monotonic_ns();
    cam.begin(t0.load());
    int taken = 0;
    for (int i = 0; i < 4000 && taken < 3; ++i)  // waits for frames, not for a time
      if (cam.wait_for_frame(core::monotonic_ns() + 50'000'000) && cam.take()) ++taken;
    cam.stop();
    ASSERT_EQ(taken, 3) << cam.error();
    const std::lock_guard lock(m);
    // Per exposure, its asks in order (the last one is what was filmed). What is checked is the
    // logic, not the timing (a loaded machine may delay any ask): asks from the exposure on; the
    // asks stop at the first exact truth; a held truth is filmed only at the end of the wait.
    std::map<std::int64_t, std::vector<Ask>> by_exposure;
    for (const Ask& a : asks) {
      EXPECT_GE(a.after, 0) << "asked before the exposure";
      by_exposure[a.exposure].push_back(a);
    }
    int polled = 0, exact = 0, waited = 0;
    for (const auto& [exposure, list] : by_exposure) {
      for (std::size_t k = 0; k + 1 < list.size(); ++k)
        EXPECT_NE(list[k].had, Truth::kExact) << "asked again after the exact truth";
      if (list.size() >= 2) ++polled;
      if (list.back().had == Truth::kExact) ++exact;
      if (list.back().after >= params.truth_wait_ns - params.truth_poll_ns) ++waited;
      if (!ever_exact) {
        EXPECT_EQ(list.back().had, Truth::kHeld);
      }
    }
    EXPECT_GE(polled, 1);  // asked again, not one late look
    if (ever_exact) {
      EXPECT_GE(exact, 1);
    } else {
      EXPECT_GE(waited, 1);  // the held truth taken at the end of the wait
    }
  }
  CameraThreadParams bad;
  bad.truth_poll_ns = 0;
  auto refused = filmed.prepare(filmed.nominal_from(nullptr), bad);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("truth_poll_ns"), std::string::npos) << refused.error().message;
}

// The frame thread sleeps in wait_for_frame until a frame is published (it is woken, not polling):
// each wait with a far deadline returns with a frame to take; a camera that has not begun gives
// none by the deadline; a stopped one wakes its waiter at once.
TEST(CameraThread, WaitForFrameWakesAtThePublicationAndEndsWithTheThread) {
  const Filmed filmed;
  std::atomic<std::int64_t> t0{0};
  const TruthAt truth_at = filmed.nominal_from(&t0);
  CameraThreadParams params;
  params.fps = 20;
  auto thread = filmed.prepare(truth_at, params);
  ASSERT_TRUE(thread.ok()) << thread.error().message;
  CameraThread& cam = *thread.value();
  EXPECT_FALSE(cam.wait_for_frame(core::monotonic_ns() + 100'000'000));  // not begun: no frame
  EXPECT_FALSE(cam.take());
  t0 = core::monotonic_ns();
  cam.begin(t0.load());
  constexpr std::int64_t kFar = 60'000'000'000;  // a minute: only a frame ends these waits
  std::uint64_t last = 0;
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(cam.wait_for_frame(core::monotonic_ns() + kFar)) << cam.error();
    ASSERT_TRUE(cam.take());
    if (k > 0) {
      EXPECT_GT(cam.frame().index, last);
    }
    last = cam.frame().index;
  }
  // Stopped from another thread while the frame thread waits: the waiter is woken.
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    cam.stop();
  });
  for (int k = 0; k < 100 && cam.wait_for_frame(core::monotonic_ns() + kFar); ++k) (void)cam.take();
  const std::int64_t t_woken = core::monotonic_ns();
  stopper.join();
  EXPECT_FALSE(cam.wait_for_frame(core::monotonic_ns() + kFar));  // ended: returns, no frame
  EXPECT_LT(core::monotonic_ns() - t_woken, kFar / 2);
}

// A frame taken and held (CameraThread::shared) is not filmed over while the camera goes on: its
// index, exposure and image stay as they were when it was taken, however many frames come after.
TEST(CameraThread, AHeldFrameIsNotFilmedOver) {
  const Filmed filmed;
  CameraThreadParams params;
  params.fps = 60;
  params.t0_ns = core::monotonic_ns();
  const std::atomic<std::int64_t> t0{params.t0_ns};
  const TruthAt truth_at = filmed.nominal_from(&t0);
  auto thread = filmed.start(truth_at, params);
  ASSERT_TRUE(thread.ok()) << thread.error().message;
  CameraThread& cam = *thread.value();
  EXPECT_EQ(cam.shared(), nullptr);  // nothing taken yet
  struct Held {
    std::shared_ptr<const FilmedFrame> frame;
    std::uint64_t index;
    std::int64_t t_exposure_ns;
    cv::Mat image;  // a deep copy made when it was taken
  };
  std::vector<Held> held;
  for (int i = 0; i < 4000 && held.size() < 4; ++i) {  // waits for frames, not for a time
    if (cam.take()) {
      const auto f = cam.shared();
      ASSERT_NE(f, nullptr);
      EXPECT_EQ(f.get(), &cam.frame());
      if (held.empty() || f->index >= held.back().index + 2)  // frames apart (the camera went on)
        held.push_back({f, f->index, f->t_exposure_ns, f->frame.bgr.clone()});
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(3));
  }
  // Let the camera film a few more frames over whatever it may still reuse.
  const std::uint64_t so_far = cam.filmed();
  for (int i = 0; i < 4000 && cam.filmed() < so_far + 5; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(3));
  cam.stop();
  ASSERT_EQ(held.size(), 4u) << cam.error();
  for (const Held& h : held) {
    EXPECT_EQ(h.frame->index, h.index);
    EXPECT_EQ(h.frame->t_exposure_ns, h.t_exposure_ns);
    ASSERT_EQ(h.frame->frame.bgr.size(), h.image.size());
    EXPECT_EQ(cv::norm(h.frame->frame.bgr, h.image, cv::NORM_INF), 0.0) << "frame " << h.index;
  }
  EXPECT_NE(held.front().frame.get(), held.back().frame.get());
}

// A frame is published as soon as its image is ready; its ground-truth images follow
// (FilmedFrame::truth_images). Once waited for, they are that frame's own: the mask lies where the
// image is not blue screen, at every frame taken while the camera goes on filming.
TEST(CameraThread, AFramesGroundTruthFollowsItsImageAndIsItsOwn) {
  const Filmed filmed;
  CameraThreadParams params;
  params.fps = 60;
  params.t0_ns = core::monotonic_ns();
  const std::atomic<std::int64_t> t0{params.t0_ns};
  auto thread = filmed.start(filmed.nominal_from(&t0), params);
  ASSERT_TRUE(thread.ok()) << thread.error().message;
  CameraThread& cam = *thread.value();
  int checked = 0;
  for (int i = 0; i < 4000 && checked < 6; ++i) {  // waits for frames, not for a time
    if (!cam.wait_for_frame(core::monotonic_ns() + 50'000'000) || !cam.take()) continue;
    const auto f = cam.shared();
    ASSERT_NE(f, nullptr);
    const SyntheticFrame& images = f->wait_for_truth_images();
    ASSERT_TRUE(f->truth_images.done());
    ASSERT_EQ(images.mask.size(), images.bgr.size()) << cam.error();
    // Not blue screen: blue well above red in the screen's colour, below it on skin.
    std::vector<cv::Mat> ch;
    cv::split(images.bgr, ch);
    cv::Mat screen = ch[0] > ch[2] + 60;
    const double hand_px = cv::countNonZero(images.mask);
    ASSERT_GT(hand_px, 5000);
    const double wrong = cv::countNonZero(screen & images.mask) + cv::countNonZero(~screen & ~images.mask);
    EXPECT_LT(wrong / hand_px, 0.05) << "frame " << f->index;
    EXPECT_GE(f->truth_images_ms, 0.0);
    ++checked;
  }
  cam.stop();
  EXPECT_EQ(checked, 6) << cam.error();
  EXPECT_TRUE(cam.error().empty()) << cam.error();
}

}  // namespace
}  // namespace spidar::sim
