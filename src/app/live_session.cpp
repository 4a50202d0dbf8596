#include "live_session.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <future>
#include <mutex>
#include <thread>

#include "cli_support.hpp"
#include "device_backends.hpp"
#include "spidar/core/clock.hpp"
#include "spidar/core/config.hpp"
#include "spidar/device/sample_interpolation.hpp"
#include "spidar/device/simulated_spidar.hpp"
#include "spidar/registration/metrics.hpp"
#include "spidar/sim/camera_thread.hpp"
#include "spidar/vision/camera_config.hpp"
#include "spidar/vision/capture.hpp"
#include "spidar/vision/vision_config.hpp"

namespace spidar::app {

/// Where camera frames come from: the synthetic camera or a real one (device or file).
struct LiveSession::FrameSource {
  virtual ~FrameSource() = default;
  virtual Status start(std::int64_t t0_ns) = 0;
  /// The newest frame since the last call, if any.
  virtual bool take(cv::Mat* bgr, std::int64_t* t_exposure_ns) = 0;
  virtual bool ended() const = 0;
  virtual std::string error() const = 0;
  virtual std::uint64_t delivered() const = 0;
  virtual void stop() = 0;
};

namespace {

/// The simulated rig's camera thread: films the simulated user's true hands.
class SyntheticSource final : public LiveSession::FrameSource {
 public:
  SyntheticSource(const vision::Camera& camera, const std::array<hand::HandModel, 2>& truth,
                  const sim::RubiksTask& task, device::SimulatedSpidar& dev, double fps,
                  std::uint64_t seed)
      : camera_(camera), truth_(truth), task_(task), dev_(dev), fps_(fps), seed_(seed) {}
  Status start(std::int64_t t0_ns) override {
    truth_buf_.resize(1000);
    sim::TruthAt truth_at = [this](std::int64_t t_ns, std::span<Vec3> out) {
      const std::size_t n = dev_.truth_samples(truth_buf_.data(), truth_buf_.size());
      const auto s = device::interpolate_samples({truth_buf_.data(), n}, t_ns);
      if (!s) return false;
      for (std::size_t f = 0; f < out.size() && f < 8; ++f)
        out[f] = Vec3(s->p_W[f][0], s->p_W[f][1], s->p_W[f][2]);
      return true;
    };
    sim::SyntheticCameraParams cp;
    cp.seed = seed_;
    sim::CameraThreadParams ctp;
    ctp.fps = fps_;
    ctp.t0_ns = t0_ns;
    auto r = sim::CameraThread::start(camera_, truth_, cp, task_, truth_at, ctp);
    if (!r) return r.error();
    thread_ = std::move(r).value();
    return Ok{};
  }
  bool take(cv::Mat* bgr, std::int64_t* t) override {
    if (!thread_ || !thread_->take()) return false;
    thread_->frame().frame.bgr.copyTo(*bgr);
    *t = thread_->frame().t_exposure_ns;
    return true;
  }
  bool ended() const override { return stopped_ && !thread_->error().empty(); }
  std::string error() const override { return stopped_ && thread_ ? thread_->error() : std::string(); }
  std::uint64_t delivered() const override { return thread_ ? thread_->filmed() : 0; }
  void stop() override {
    if (thread_ && !stopped_) thread_->stop();
    stopped_ = true;
  }

 private:
  vision::Camera camera_;
  std::array<hand::HandModel, 2> truth_;
  const sim::RubiksTask& task_;
  device::SimulatedSpidar& dev_;
  double fps_;
  std::uint64_t seed_;
  std::vector<device::FingertipSample> truth_buf_;
  std::unique_ptr<sim::CameraThread> thread_;
  bool stopped_ = false;
};

/// A frame source whose own thread produces frames: the newest one waits in a slot for the frame
/// thread (older ones are dropped, as a camera's are). Derived classes start `thread_` and call
/// stop() in their destructor, before their own members go.
class ThreadedSource : public LiveSession::FrameSource {
 public:
  bool take(cv::Mat* bgr, std::int64_t* t) override {
    std::lock_guard lock(mutex_);
    if (!fresh_) return false;
    fresh_ = false;
    latest_.copyTo(*bgr);
    *t = latest_t_;
    return true;
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
    }
    delivered_.fetch_add(1, std::memory_order_acq_rel);
  }
  void fail(const std::string& message) {
    std::lock_guard lock(mutex_);
    error_ = message;
  }
  void finish() { done_.store(true, std::memory_order_release); }
  bool stopping() const { return stop_.load(std::memory_order_acquire); }
  std::thread thread_;

 private:
  mutable std::mutex mutex_;
  cv::Mat latest_;
  std::int64_t latest_t_ = 0;
  bool fresh_ = false;
  std::string error_;
  std::atomic<bool> stop_{false}, done_{false};
  std::atomic<std::uint64_t> delivered_{0};
};

/// A real camera (V4L2 device) or a video file, read in its own thread. A device's frames carry
/// the host time they were grabbed at; a file's frame k is shown at start + k / fps.
class CaptureSource final : public ThreadedSource {
 public:
  explicit CaptureSource(vision::Capture capture) : capture_(std::move(capture)) {}
  ~CaptureSource() override { stop(); }
  Status start(std::int64_t t0_ns) override {
    t0_ns_ = t0_ns;
    thread_ = std::thread([this] { run(); });
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

/// The synthetic camera filming the interactively controlled hands (their commanded posture).
class InteractiveSource final : public ThreadedSource {
 public:
  InteractiveSource(const vision::Camera& camera, const session::InteractiveHands& hands, double fps, std::uint64_t seed)
      : camera_(camera), hands_(hands), fps_(fps), seed_(seed) {}
  ~InteractiveSource() override { stop(); }
  Status start(std::int64_t t0_ns) override {
    std::promise<Status> ready;
    auto done = ready.get_future();
    thread_ = std::thread([this, t0_ns, &ready] { run(t0_ns, ready); });
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
  const session::InteractiveHands& hands_;
  double fps_;
  std::uint64_t seed_;
};

}  // namespace

double silhouette_iou(const pipeline::FrameResult& r, cv::Mat* scratch) {
  if (r.virt.hand_id.empty() || r.key.silhouette.empty()) return 0.0;
  *scratch = r.virt.hand_id != 0;  // 255 where a fitted hand (or its forearm) is nearest
  return registration::mask_iou(*scratch, r.key.silhouette);
}

pipeline::FramePipelineParams live_pipeline_params(const LiveConfig& c,
                                                   const std::array<Vec3, 2>& initial_r_W_hand) {
  const auto vision_cfg = vision::load_vision_config(c.vision_config);
  const auto reg_root = core::ConfigNode::LoadFile(c.registration_config);
  pipeline::FramePipelineParams pp;
  pp.chroma_key = vision_cfg.chroma_key;
  pp.bracelet = vision_cfg.bracelet;
  pp.registration = registration::parse_registration_params(reg_root["registration"]);
  pp.registration.silhouette_term = c.silhouette;
  auto mode = render::parse_composite_mode(c.compositor);
  if (!mode) throw UsageError("compositor.mode: " + mode.error().message);
  pp.compositor.mode = *mode;
  pp.initial_r_W_hand = initial_r_W_hand;
  return pp;
}

std::unique_ptr<LiveSession> LiveSession::create(const LiveConfig& c, render::Context& context,
                                                 const LiveSessionOptions& options) {
  if (!options.record_dir.empty() && std::filesystem::exists(std::filesystem::path(options.record_dir) / "session.json"))
    throw UsageError("--record " + options.record_dir + ": already holds a recording (session.json); choose a new folder");
  std::unique_ptr<LiveSession> s(new LiveSession());
  s->config_ = c;
  s->options_ = options;
  s->context_ = &context;
  s->device_config_ = strings::load_device_config(c.device_config);
  if (s->device_config_.fingers.size() != 8)
    throw UsageError(c.device_config + ": the live session needs 8 fingers (thumb, index, middle, "
                     "ring of both hands), got " + std::to_string(s->device_config_.fingers.size()));
  s->camera_ = session::scaled_camera(vision::load_camera_file(c.camera_calibration).camera, c.width, c.height);
  s->models_ = session::hand_models(c.hands_file, c.model_profile, false);
  s->user_models_ = session::hand_models(c.hands_file, c.user_profile, true);

  // --- physics ---
  physics::WorldParams wp;
  auto world_r = physics::World::Load(c.scene, wp);
  if (!world_r) throw UsageError(c.source + ": scene: " + world_r.error().message);
  s->world_ = std::move(world_r).value();
  if (auto cube_r = physics::RubiksCube::Attach(*s->world_)) s->cube_ = std::move(cube_r).value();
  Pose X_cube0;
  s->task_ = session::make_scripted_task(*s->world_, s->cube_, wp.proxy.radius, s->user_models_, &X_cube0);
  s->cube_monitor_ = std::make_unique<session::CubeMonitor>(&s->cube_, X_cube0);
  if (s->cube_) s->task_->track(&s->cube_monitor_->pose());

  // --- device and servo loop ---
  device::SimulatedSpidar* simulated = nullptr;
  if (c.user_mode == "interactive") {
    // Open: the script's start (withdrawn, relaxed); closed: its grip on the cube.
    std::array<hand::HandParams, 2> open, closed;
    for (int h = 0; h < 2; ++h) {
      const auto side = h == 0 ? hand::Side::kLeft : hand::Side::kRight;
      open[h] = s->task_->nominal(0.0, side);
      closed[h] = s->task_->nominal(2.0, side);
    }
    s->interactive_ = std::make_shared<session::InteractiveHands>(s->user_models_, open, closed);
  }
  if (c.backend == "sim") {
    device::SimulatedSpidarParams dp;
    dp.seed = c.seed;
    std::shared_ptr<device::FingertipSource> user = s->task_;
    if (s->interactive_) user = s->interactive_;
    auto dev = std::make_unique<device::SimulatedSpidar>(s->device_config_, dp, user);
    simulated = dev.get();
    s->device_ = std::move(dev);
  } else {
    BackendArgs a;
    a.backend = "serial";
    a.port = c.port;
    a.baud = c.baud;
    s->device_ = make_backend(a, s->device_config_);
  }
  // Every cycle's counts and commands pass through a lock-free ring: the recorder drains it, the
  // GUI's string calibration reads the newest counts from it.
  s->recording_device_ = std::make_unique<RecordingDevice>(*s->device_);
  device::Device* dev = s->recording_device_.get();
  device::ServoConfig servo;
  servo.rate_hz = c.rate_hz;
  servo.force_timeout_s = 0.05;
  s->bridge_ = std::make_shared<sim::HapticForces>(wp.coupling, servo.rate_hz);
  s->physics_ = std::make_unique<sim::PhysicsThread>(*s->world_, *s->bridge_);
  s->physics_->set_snapshot_proxies(false);
  s->physics_->set_realtime_priority(60);
  session::CubeMonitor* monitor = s->cube_monitor_.get();
  s->physics_->set_before_step([monitor](physics::World& w) { monitor->before_step(w); });
  s->loop_ = std::make_unique<device::ServoLoop>(*dev, s->device_config_, servo, s->bridge_);

  // --- camera ---
  if (c.camera_source == "synthetic" && s->interactive_) {
    s->source_ = std::make_unique<InteractiveSource>(s->camera_, *s->interactive_, c.fps, c.seed);
  } else if (c.camera_source == "synthetic") {
    s->source_ = std::make_unique<SyntheticSource>(s->camera_, s->user_models_, *s->task_, *simulated,
                                                   c.fps, c.seed);
  } else {
    vision::CaptureOptions co;
    co.fallback_fps = c.fps;
    co.width = c.width;
    co.height = c.height;
    const std::string name = c.camera_source == "device" ? c.camera_device : c.camera_file;
    auto cap = vision::Capture::open(name, co);
    if (!cap) throw UsageError(c.source + ": camera: " + cap.error().message);
    if (cap->width() > 0 && (cap->width() != c.width || cap->height() != c.height))
      throw UsageError(c.source + ": camera: '" + name + "' gives " + std::to_string(cap->width()) + "x" +
                       std::to_string(cap->height()) + " px, the config says " + std::to_string(c.width) +
                       "x" + std::to_string(c.height) + " (set camera.width and camera.height to match)");
    s->source_ = std::make_unique<CaptureSource>(std::move(cap).value());
  }

  // --- frame pipeline ---
  std::array<Vec3, 2> r0;
  for (int h = 0; h < 2; ++h)
    r0[h] = s->task_->nominal(0.0, h == 0 ? hand::Side::kLeft : hand::Side::kRight).r_W_hand();
  auto pipe_r = pipeline::FramePipeline::create(context, s->camera_, s->models_, live_pipeline_params(c, r0));
  if (!pipe_r) throw UsageError(pipe_r.error().message);
  s->pipe_ = std::move(pipe_r).value();

  if (!options.record_dir.empty()) {
    RecordingMeta meta;
    meta.config_yaml = live_config_yaml(c);
    meta.width = c.width;
    meta.height = c.height;
    meta.fps = c.fps;
    meta.string_count = s->device_config_.string_count();
    meta.finger_count = static_cast<int>(s->device_config_.fingers.size());
    meta.initial_r_W_hand = r0;
    meta.device_name = c.backend == "sim" ? "simulated " + s->device_config_.name : "serial " + c.port;
    s->recorder_ = std::make_unique<SessionRecorder>(options.record_dir, options.record_frames, meta);
  }
  s->servo_buf_.resize(1000);
  return s;
}

LiveSession::~LiveSession() { stop(); }

void LiveSession::start() {
  if (started_) return;
  if (auto st = device_->open(); !st) throw UsageError("device: " + st.error().message);
  t_open_ns_ = core::monotonic_ns();
  started_ = true;
  physics_->start();
  if (auto st = loop_->start(); !st) {
    stop();
    throw UsageError("servo loop: " + st.error().message);
  }
  if (recorder_) recorder_->start(recording_device_.get(), loop_.get());
  if (auto st = source_->start(t_open_ns_); !st) {
    stop();
    throw SpidarError("camera: " + st.error().message);
  }
}

bool LiveSession::running() const {
  return started_ && !stopped_ && loop_->running() && !source_->ended();
}

bool LiveSession::camera_ended() const { return source_ && source_->ended(); }

std::string LiveSession::error() const {
  std::string e;
  if (loop_ && loop_->faults() != 0) e = "servo loop fault: " + device::fault_names(loop_->faults());
  if (const std::string ce = source_ ? source_->error() : ""; !ce.empty())
    e += (e.empty() ? "" : "; ") + std::string("camera: ") + ce;
  return e;
}

double LiveSession::seconds() const {
  return started_ ? core::ns_to_s(core::monotonic_ns() - t_open_ns_) : 0.0;
}

std::optional<DeviceCycleRecord> LiveSession::newest_device_cycle() const {
  DeviceCycleRecord r;
  if (recording_device_->ring().newest(&r, 1) == 1) return r;
  return std::nullopt;
}

std::uint64_t LiveSession::camera_frames() const { return source_ ? source_->delivered() : 0; }

std::optional<session::CubeStatus> LiveSession::cube_status() const { return cube_monitor_->status().read(); }

sim::PhysicsThreadStats LiveSession::physics_stats() const { return physics_->stats(); }

bool LiveSession::step() {
  if (!started_ || stopped_) return false;
  cv::Mat bgr;
  std::int64_t t_exp = 0;
  if (!source_->take(&bgr, &t_exp)) return false;
  if (bgr.cols != config_.width || bgr.rows != config_.height)
    throw SpidarError("camera: a frame of " + std::to_string(bgr.cols) + "x" + std::to_string(bgr.rows) +
                      " px, expected " + std::to_string(config_.width) + "x" + std::to_string(config_.height));
  const std::size_t ns = loop_->newest_samples(servo_buf_.data(), servo_buf_.size());
  const auto measured = device::interpolate_samples({servo_buf_.data(), ns}, t_exp);
  if (!measured) return false;  // no servo samples around the exposure (a stall): skip the frame
  physics_->snapshots().update();
  scene_ = physics_->snapshots().front();
  if (auto st = pipe_->process(bgr, *measured, scene_, &result_); !st) throw SpidarError(st.error().message);
  const std::int64_t done = core::monotonic_ns();
  measured_ = *measured;
  camera_image_ = bgr;

  LiveFrameStats m;
  m.t_s = core::ns_to_s(t_exp - t_open_ns_);
  m.iou = silhouette_iou(result_, &iou_scratch_);
  for (int h = 0; h < 2; ++h) {
    m.terms[h] = result_.fits[h].terms;
    m.iterations[h] = result_.fits[h].iterations;
  }
  m.latency_ms = core::ns_to_s(done - t_exp) * 1e3;
  m.pipeline_ms = result_.timings.total_ms;
  m.registration_ms = result_.timings.registration_ms;
  {  // servo timing since the last frame, from the published samples
    const session::ServoTiming st = session::servo_timing_since({servo_buf_.data(), ns}, config_.rate_hz, &last_servo_t_);
    m.servo_rate_hz = st.rate_hz;
    m.servo_jitter_max_us = st.jitter_max_us;
  }
  history_.push_back(m);

  if (recorder_) {
    FrameRecord fr;
    fr.index = static_cast<std::int64_t>(frames_);
    fr.t_exposure_ns = t_exp;
    fr.bgr = bgr;  // a fresh Mat per frame (take() copies into a new one): no clone needed
    fr.measured = measured_;
    fr.scene_poses.reserve(scene_.shapes.size());
    for (const Shape& sh : scene_.shapes) fr.scene_poses.push_back(sh.X_WS);
    fr.hands = result_.hands;
    fr.fits = result_.fits;
    recorder_->add_frame(std::move(fr));
  }
  ++frames_;
  return true;
}

void LiveSession::stop() {
  if (stopped_) return;
  stopped_ = true;
  if (source_) source_->stop();
  if (loop_) loop_->stop();
  if (physics_) physics_->stop();
  if (device_) device_->close();
  if (recorder_) recorder_->stop();
}

}  // namespace spidar::app
