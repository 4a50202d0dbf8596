// Frame sources whose own thread produces frames: a real camera or video file, and the synthetic
// camera filming the interactively controlled hands.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <future>
#include <mutex>
#include <thread>

#include "spidar/core/clock.hpp"
#include "spidar/core/thread_name.hpp"
#include "spidar/core/wait_until.hpp"
#include "spidar/render/context.hpp"
#include "spidar/session/frame_source.hpp"
#include "spidar/session/interactive_hands.hpp"
#include "spidar/sim/synthetic_camera.hpp"

namespace spidar::session {
namespace {

/// The newest frame waits in a slot for the frame thread (older ones are dropped). Derived
/// classes start `thread_` and call stop() in their destructor, before their own members go.
class ThreadedSource : public FrameSource {
 public:
  bool take(CameraFrame* out) override {
    std::lock_guard lock(mutex_);
    if (!fresh_) return false;
    fresh_ = false;
    out->bgr = cv::Mat();  // a fresh image per frame: a sink may keep the previous one
    latest_.copyTo(out->bgr);
    out->t_exposure_ns = latest_t_;
    out->filmed = nullptr;
    out->filmed_hold.reset();
    return true;
  }
  void wait_for_frame(std::int64_t deadline_ns) override {
    std::unique_lock lock(mutex_);
    core::wait_until_ns(arrived_, lock, deadline_ns, [&] { return fresh_ || done_.load(std::memory_order_acquire); });
  }
  bool ended() const override { return done_.load(std::memory_order_acquire); }
  std::string error() const override {
    std::lock_guard lock(mutex_);
    return error_;
  }
  std::uint64_t delivered() const override { return delivered_.load(std::memory_order_acquire); }
  void stop() override {
    stop_.store(true, std::memory_order_release);
    if (thread_.joinable()) thread_.join();
  }

 protected:
  /// The producing thread: hands over a frame (copied) with its exposure time [ns, monotonic].
  void publish(const cv::Mat& bgr, std::int64_t t_ns) {
    {
      std::lock_guard lock(mutex_);
      bgr.copyTo(latest_);
      latest_t_ = t_ns;
      fresh_ = true;
      delivered_.fetch_add(1, std::memory_order_acq_rel);  // counted before anyone can take it
    }
    arrived_.notify_all();
  }
  void fail(const std::string& message) {
    std::lock_guard lock(mutex_);
    error_ = message;
  }
  void finish() {
    {
      std::lock_guard lock(mutex_);  // a waiter between its check and its wait misses no wake-up
      done_.store(true, std::memory_order_release);
    }
    arrived_.notify_all();
  }
  bool stopping() const { return stop_.load(std::memory_order_acquire); }
  std::thread thread_;

 private:
  mutable std::mutex mutex_;
  std::condition_variable arrived_;  ///< a frame published or the source finished (mutex_)
  cv::Mat latest_;
  std::int64_t latest_t_ = 0;
  bool fresh_ = false;
  std::string error_;
  std::atomic<bool> stop_{false}, done_{false};
  std::atomic<std::uint64_t> delivered_{0};
};

class CaptureSource final : public ThreadedSource {
 public:
  explicit CaptureSource(vision::Capture capture) : capture_(std::move(capture)) {}
  ~CaptureSource() override { stop(); }
  Status start(std::int64_t t0_ns) override {
    t0_ns_ = t0_ns;
    thread_ = std::thread([this] {
      core::set_thread_name("spidar-capture");
      run();
    });
    return Ok{};
  }

 private:
  void run() {
    const bool file = capture_.kind() != vision::SourceKind::kDevice;
    while (!stopping()) {
      auto f = capture_.read();
      if (!f) {
        if (!capture_.at_end()) fail(f.error().message);  // end of file is not an error
        break;
      }
      std::int64_t t = file ? t0_ns_ + static_cast<std::int64_t>(f->t_s * 1e9)
                            : static_cast<std::int64_t>(f->t_s * 1e9);
      if (file) {  // play at the file's rate
        while (core::monotonic_ns() < t && !stopping())
          std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
      publish(f->image, t);
    }
    finish();
  }

  vision::Capture capture_;
  std::int64_t t0_ns_ = 0;
};

class InteractiveSource final : public ThreadedSource {
 public:
  InteractiveSource(const vision::Camera& camera, const InteractiveHands& hands, double fps,
                    std::uint64_t seed)
      : camera_(camera), hands_(hands), fps_(fps), seed_(seed) {}
  ~InteractiveSource() override { stop(); }
  Status start(std::int64_t t0_ns) override {
    std::promise<Status> ready;
    auto done = ready.get_future();
    thread_ = std::thread([this, t0_ns, &ready] {
      core::set_thread_name("spidar-camera");
      run(t0_ns, ready);
    });
    Status st = done.get();
    if (!st) stop();
    return st;
  }

 private:
  void run(std::int64_t t0_ns, std::promise<Status>& ready) {
    auto ctx = render::Context::create_headless();
    if (!ctx) return ready.set_value(Error{"interactive camera: OpenGL: " + ctx.error().message});
    sim::SyntheticCameraParams cp;
    cp.seed = seed_;
    auto film = sim::SyntheticCamera::create(*ctx.value(), camera_, hands_.models(), cp);
    if (!film) return ready.set_value(Error{"interactive camera: " + film.error().message});
    ready.set_value(Ok{});
    const auto period_ns = static_cast<std::int64_t>(1e9 / fps_);
    std::int64_t t_exp = t0_ns;
    sim::SyntheticFrame frame;
    while (!stopping()) {
      core::sleep_until_ns(t_exp);
      if (stopping()) break;
      const auto q = hands_.pose(hands_.controls());
      const sim::HandPoses poses{&q[0], &q[1]};
      if (auto st = film.value()->film(poses, &frame); !st) {
        fail(st.error().message);
        break;
      }
      publish(frame.bgr, t_exp);
      t_exp += period_ns;
      while (t_exp < core::monotonic_ns()) t_exp += period_ns;  // a slow frame drops exposures
    }
    finish();
  }

  vision::Camera camera_;
  const InteractiveHands& hands_;
  double fps_;
  std::uint64_t seed_;
};

}  // namespace

std::unique_ptr<FrameSource> make_capture_source(vision::Capture capture) {
  return std::make_unique<CaptureSource>(std::move(capture));
}

std::unique_ptr<FrameSource> make_interactive_source(const vision::Camera& camera,
                                                     const InteractiveHands& hands, double fps,
                                                     std::uint64_t seed) {
  return std::make_unique<InteractiveSource>(camera, hands, fps, seed);
}

}  // namespace spidar::session
