#include "spidar/session/live_session.hpp"

#include <filesystem>

#include "spidar/session/device_backends.hpp"
#include "spidar/session/rig_inputs.hpp"
#include "spidar/vision/camera_config.hpp"
#include "spidar/vision/capture.hpp"

namespace spidar::session {

pipeline::FramePipelineParams live_pipeline_params(const LiveConfig& c,
                                                   const std::array<Vec3, 2>& initial_r_W_hand) {
  auto mode = render::parse_composite_mode(c.compositor);
  if (!mode) throw SpidarError("compositor.mode: " + mode.error().message);
  return pipeline_params(c.vision_config, c.registration_config, c.silhouette, *mode,
                                  initial_r_W_hand);
}

namespace {

/// The configured real camera (V4L2 device or video file), checked against the config's size.
std::unique_ptr<FrameSource> capture_source(const LiveConfig& c) {
  vision::CaptureOptions co;
  co.fallback_fps = c.fps;
  co.width = c.width;
  co.height = c.height;
  const std::string name = c.camera_source == "device" ? c.camera_device : c.camera_file;
  auto cap = vision::Capture::open(name, co);
  if (!cap) throw SpidarError(c.source + ": camera: " + cap.error().message);
  if (cap->width() > 0 && (cap->width() != c.width || cap->height() != c.height))
    throw SpidarError(c.source + ": camera: '" + name + "' gives " + std::to_string(cap->width()) + "x" +
                     std::to_string(cap->height()) + " px, the config says " + std::to_string(c.width) +
                     "x" + std::to_string(c.height) + " (set camera.width and camera.height to match)");
  return make_capture_source(std::move(cap).value());
}

}  // namespace

std::unique_ptr<LiveSession> LiveSession::create(const LiveConfig& c, render::Context& context,
                                                 const LiveSessionOptions& options) {
  if (!options.record_dir.empty() && std::filesystem::exists(std::filesystem::path(options.record_dir) / "session.json"))
    throw SpidarError("--record " + options.record_dir + ": already holds a recording (session.json); choose a new folder");
  std::unique_ptr<LiveSession> s(new LiveSession());
  s->config_ = c;
  const strings::DeviceConfig device_config = strings::load_device_config(c.device_config);
  if (device_config.fingers.size() != 8)
    throw SpidarError(c.device_config + ": the live session needs 8 fingers (thumb, index, middle, "
                     "ring of both hands), got " + std::to_string(device_config.fingers.size()));
  s->camera_ = scaled_camera(vision::load_camera_file(c.camera_calibration).camera, c.width, c.height);
  s->models_ = hand_models(c.hands_file, c.model_profile, false);
  s->user_models_ = hand_models(c.hands_file, c.user_profile, true);
  auto scene_r = Scene::load(c.scene, s->user_models_);
  if (!scene_r) throw SpidarError(c.source + ": scene: " + scene_r.error().message);
  s->scene_ = std::move(scene_r).value();

  // --- the rig: simulated or serial device; synthetic, V4L2 or file camera ---
  std::unique_ptr<FrameSource> camera;
  if (c.camera_source != "synthetic") camera = capture_source(c);
  if (c.backend == "sim") {
    SimulatedRigParams rp;
    rp.seed = c.seed;
    rp.fps = c.fps;
    rp.interactive = c.user_mode == "interactive";
    s->rig_ = std::make_unique<SimulatedRig>(device_config, *s->scene_, s->camera_,
                                                      s->user_models_, rp, std::move(camera));
  } else {
    if (!camera) throw SpidarError(c.source + ": the synthetic camera needs device.backend: sim");
    BackendArgs a;
    a.backend = "serial";
    a.port = c.port;
    a.baud = c.baud;
    s->rig_ = std::make_unique<HardwareRig>(device_config, make_backend(a, device_config),
                                                     std::move(camera), "serial " + c.port);
  }
  // Every cycle's counts and commands pass through a lock-free ring: the recorder drains it, the
  // GUI's string calibration reads the newest counts from it.
  s->recording_device_ = std::make_unique<RecordingDevice>(s->rig_->device());

  // --- the session: servo loop, physics, frame pipeline (warmed up before the clock starts) ---
  SessionParams sp;
  sp.servo.rate_hz = c.rate_hz;
  sp.servo.force_timeout_s = 0.05;
  sp.warm_up = options.warm_up;
  const std::array<Vec3, 2> r0 = s->scene_->initial_r_W_hand();
  sp.pipeline = live_pipeline_params(c, r0);
  s->session_ = Session::create(*s->rig_, *s->scene_, context, s->camera_, s->models_, sp,
                                         s->recording_device_.get());
  s->session_->add_sink(s->view_);

  if (!options.record_dir.empty()) {
    RecorderSetup meta;
    meta.config_yaml = live_config_yaml(c);
    meta.width = c.width;
    meta.height = c.height;
    meta.fps = c.fps;
    meta.string_count = device_config.string_count();
    meta.finger_count = static_cast<int>(device_config.fingers.size());
    meta.initial_r_W_hand = r0;
    meta.device_name = c.backend == "sim" ? "simulated " + device_config.name : "serial " + c.port;
    s->recorder_ = std::make_unique<SessionRecorder>(options.record_dir, options.record_frames, meta,
                                                     *s->recording_device_, s->session_->servo());
    s->session_->add_sink(*s->recorder_);
  }
  return s;
}

LiveSession::~LiveSession() { stop(); }

void LiveSession::start() { session_->start(); }

std::string LiveSession::error() const {
  std::string e;
  if (session_->servo().faults() != 0) e = "servo loop fault: " + device::fault_names(session_->servo().faults());
  if (const std::string ce = rig_->camera().error(); !ce.empty())
    e += (e.empty() ? "" : "; ") + std::string("camera: ") + ce;
  return e;
}

std::optional<DeviceCycleRecord> LiveSession::newest_device_cycle() const {
  DeviceCycleRecord r;
  if (recording_device_->ring().newest(&r, 1) == 1) return r;
  return std::nullopt;
}

bool LiveSession::step() { return session_->step() == Session::Step::kFrame; }
void LiveSession::wait_for_frame(std::int64_t deadline_ns) { session_->wait_for_frame(deadline_ns); }

void LiveSession::stop() {
  if (!session_) return;
  session_->stop();
  if (recorder_) recorder_->stop();
}

}  // namespace spidar::session
