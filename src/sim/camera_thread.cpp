#include "spidar/sim/camera_thread.hpp"
#include "spidar/core/thread_name.hpp"

#include <algorithm>
#include <chrono>
#include <future>
#include <utility>
#include <vector>

#include "spidar/core/clock.hpp"
#include "spidar/core/realtime.hpp"
#include "spidar/core/wait_until.hpp"
#include "spidar/render/context.hpp"

namespace spidar::sim {

void copy_filmed_frame(const FilmedFrame& from, FilmedFrame* to) {
  from.wait_for_truth_images();
  to->index = from.index;
  to->t_exposure_ns = from.t_exposure_ns;
  to->t_script_s = from.t_script_s;
  for (auto [a, b] : {std::pair{&from.frame.bgr, &to->frame.bgr}, {&from.frame.mask, &to->frame.mask},
                      {&from.frame.hand_index, &to->frame.hand_index},
                      {&from.frame.hand_only, &to->frame.hand_only}, {&from.frame.depth, &to->frame.depth},
                      {&from.frame.hand_id, &to->frame.hand_id}}) {
    if (a->empty()) b->release();
    else a->copyTo(*b);
  }
  to->frame.toward_elbow_W = from.frame.toward_elbow_W;
  to->truth = from.truth;
  to->cap_residual_m = from.cap_residual_m;
  to->film_ms = from.film_ms;
  to->truth_images_ms = from.truth_images_ms;
  to->truth_images.set();
}

Result<std::unique_ptr<CameraThread>> CameraThread::prepare(
    const vision::Camera& camera, const std::array<hand::HandModel, 2>& truth,
    const SyntheticCameraParams& film_params, const RubiksTask& task, TruthAt truth_at,
    const CameraThreadParams& params) {
  if (!(params.fps > 0 && params.fps <= 1000)) return Error{"camera thread: fps must be in (0, 1000]"};
  if (!truth_at) return Error{"camera thread: no ground-truth source given"};
  for (const auto& [name, ns] : {std::pair{"readout_ns", params.readout_ns}, std::pair{"truth_wait_ns", params.truth_wait_ns},
                                 std::pair{"first_exposure_ns", params.first_exposure_ns}})
    if (ns < 0 || ns > 1'000'000'000)
      return Error{std::string("camera thread: ") + name + " must be in [0, 1e9] ns, got " + std::to_string(ns)};
  if (params.truth_poll_ns < 1000 || params.truth_poll_ns > 1'000'000'000)
    return Error{"camera thread: truth_poll_ns must be in [1e3, 1e9] ns, got " + std::to_string(params.truth_poll_ns)};
  if (params.fifo_priority < 0 || params.fifo_priority > 99)
    return Error{"camera thread: fifo_priority must be in 0..99 (0: none), got " + std::to_string(params.fifo_priority)};
  if (params.nice < -20 || params.nice > 19)
    return Error{"camera thread: nice must be in -20..19, got " + std::to_string(params.nice)};
  if (params.warm_frames < 0 || params.warm_frames > 64)
    return Error{"camera thread: warm_frames must be in 0..64, got " + std::to_string(params.warm_frames)};
  std::unique_ptr<CameraThread> c(new CameraThread());
  c->params_ = params;
  c->truth_at_ = std::move(truth_at);
  std::promise<Status> ready;
  auto started = ready.get_future();
  CameraThread* self = c.get();
  c->thread_ = std::thread([self, camera, truth, film_params, &task, &ready] {
    self->run(camera, truth, film_params, task, [&ready](Status s) { ready.set_value(std::move(s)); });
  });
  Status s = started.get();
  if (!s) {
    c->stop();
    return s.error();
  }
  return c;
}

Result<std::unique_ptr<CameraThread>> CameraThread::start(
    const vision::Camera& camera, const std::array<hand::HandModel, 2>& truth,
    const SyntheticCameraParams& film_params, const RubiksTask& task, TruthAt truth_at,
    const CameraThreadParams& params) {
  auto c = prepare(camera, truth, film_params, task, std::move(truth_at), params);
  if (c) c.value()->begin(params.t0_ns);
  return c;
}

void CameraThread::begin(std::int64_t t0_ns) {
  {
    std::lock_guard lock(gate_mutex_);
    if (t0_ns_) return;
    t0_ns_ = t0_ns;
  }
  gate_.notify_all();
}

CameraThread::~CameraThread() { stop(); }

void CameraThread::stop() {
  {
    std::lock_guard lock(gate_mutex_);
    stop_.store(true, std::memory_order_release);
  }
  gate_.notify_all();
  if (thread_.joinable()) thread_.join();
}

bool CameraThread::wait_for_frame(std::int64_t deadline_ns) {
  std::unique_lock lock(newest_mutex_);
  core::wait_until_ns(arrived_, lock, deadline_ns, [&] { return newest_ != nullptr || ended_; });
  return newest_ != nullptr;
}

bool CameraThread::take() {
  std::lock_guard lock(newest_mutex_);
  if (!newest_) return false;
  current_ = std::move(newest_);  // the previous one goes back to the pool once nobody holds it
  return true;
}

void CameraThread::run(const vision::Camera& camera, const std::array<hand::HandModel, 2>& truth,
                       const SyntheticCameraParams& film_params, const RubiksTask& task,
                       std::function<void(Status)> ready) {
  core::set_thread_name("spidar-camera");
  (void)core::set_nice(params_.nice);  // best effort (see CameraThreadParams::nice)
  if (params_.fifo_priority > 0) (void)core::set_fifo_priority(params_.fifo_priority);  // best effort: nice where refused
  // However the thread ends, a frame thread waiting for a frame is woken.
  struct WakeWaitersAtEnd {
    CameraThread& c;
    ~WakeWaitersAtEnd() {
      {
        std::lock_guard lock(c.newest_mutex_);
        c.ended_ = true;
      }
      c.arrived_.notify_all();
    }
  } wake_at_end{*this};
  // The GL context lives (and is current) on this thread only.
  auto ctx = render::Context::create_headless();
  if (!ctx) return ready(Error{"camera thread: OpenGL: " + ctx.error().message});
  auto film = SyntheticCamera::create(*ctx.value(), camera, truth, film_params);
  if (!film) return ready(Error{"camera thread: " + film.error().message});
  UserHands user(truth, task);
  // Frames filmed before the clock starts, at the script's first nominal poses, and thrown away:
  // the GL driver compiles its shaders at the first draw (98 ms of the first frame here), and the
  // pool's frames (CameraThreadParams::warm_frames) get their images; either would otherwise
  // skip or drop the first exposures.
  {
    const std::array<hand::HandParams, 2> q0{task.nominal(0.0, hand::Side::kLeft),
                                             task.nominal(0.0, hand::Side::kRight)};
    SyntheticFrame scratch;
    if (auto st = film.value()->film(HandPoses{&q0[0], &q0[1]}, &scratch); !st)
      return ready(Error{"camera thread: warm-up frame: " + st.error().message});
    std::vector<std::shared_ptr<FilmedFrame>> held;
    for (int k = 0; k < params_.warm_frames; ++k) {
      held.push_back(pool_.take());
      if (auto st = film.value()->film(HandPoses{&q0[0], &q0[1]}, &held.back()->frame); !st)
        return ready(Error{"camera thread: warm-up frame: " + st.error().message});
    }
  }  // back to the pool
  ready(Ok{});
  std::int64_t t0_ns = 0;
  {
    std::unique_lock lock(gate_mutex_);
    gate_.wait(lock, [this] { return t0_ns_.has_value() || stop_.load(std::memory_order_acquire); });
    if (!t0_ns_) return;  // stopped before it began
    t0_ns = *t0_ns_;
  }

  const auto period_ns = static_cast<std::int64_t>(1e9 / params_.fps);
  std::array<Vec3, 8> caps;
  std::uint64_t index = 0;
  std::int64_t t_exp = t0_ns + params_.first_exposure_ns;
  while (!stop_.load(std::memory_order_acquire)) {
    // The ground truth at the exposure: asked from the exposure on until it is exact, a held one
    // taken at the end of the wait.
    const std::int64_t give_up = t_exp + std::min(params_.truth_wait_ns, params_.readout_ns);
    core::sleep_until_ns(t_exp);
    Truth had = Truth::kNone;
    while (!stop_.load(std::memory_order_acquire)) {
      had = truth_at_(t_exp, caps);
      const std::int64_t now = core::monotonic_ns();
      if (had == Truth::kExact || now >= give_up) break;
      core::sleep_until_ns(std::min(give_up, now + params_.truth_poll_ns));
    }
    if (stop_.load(std::memory_order_acquire)) break;
    const std::int64_t t_start = core::monotonic_ns();
    if (had != Truth::kNone) {
      const double t_script = core::ns_to_s(t_exp - t0_ns);
      user.update(t_script, caps);
      std::shared_ptr<FilmedFrame> frame = pool_.take();  // nobody holds it: its buffers are reused
      FilmedFrame& out = *frame;
      out.index = index;
      out.t_exposure_ns = t_exp;
      out.t_script_s = t_script;
      out.truth = user.params();
      out.cap_residual_m = user.cap_residual_m();
      const HandPoses poses{&out.truth[0], &out.truth[1]};
      out.truth_images.reset();  // nobody sees this frame yet
      if (auto st = film.value()->film_image(poses, &out.frame); !st) {
        error_ = st.error().message;
        break;
      }
      out.film_ms = core::ns_to_s(core::monotonic_ns() - t_start) * 1e3;
      core::sleep_until_ns(t_exp + params_.readout_ns);  // not before the sensor has read it out
      const std::shared_ptr<FilmedFrame> writing = frame;  // kept from the pool until its truth is in
      {
        std::lock_guard lock(newest_mutex_);
        // Counted before anyone can take it: filmed() is never behind the frames taken.
        filmed_.fetch_add(1, std::memory_order_acq_rel);
        newest_ = std::move(frame);  // a newer frame replaces one not taken (back to the pool)
      }
      arrived_.notify_all();
      // The ground-truth images after the publication: the frame thread works on the image
      // meanwhile. Done on every path, so that no reader waits for ever.
      const std::int64_t t_truth = core::monotonic_ns();
      const Status truth_status = film.value()->film_truth(&writing->frame);
      writing->truth_images_ms = core::ns_to_s(core::monotonic_ns() - t_truth) * 1e3;
      if (!truth_status) {
        SyntheticFrame& f = writing->frame;
        for (cv::Mat* m : {&f.mask, &f.hand_index, &f.hand_only, &f.depth, &f.hand_id}) m->release();
        error_ = truth_status.error().message;
      }
      writing->truth_images.set();
      if (!truth_status) break;
    } else {
      // No fingertips yet at this exposure (the device's first samples come later on a busy
      // machine): an exposure let pass too, so a frame's index gap is always filmed + skipped.
      skipped_.fetch_add(1, std::memory_order_acq_rel);
    }
    // The next exposure; exposures already past are skipped (a stalled camera drops frames).
    ++index;
    t_exp += period_ns;
    const std::int64_t now = core::monotonic_ns();
    while (t_exp + params_.readout_ns < now) {
      t_exp += period_ns;
      ++index;
      skipped_.fetch_add(1, std::memory_order_acq_rel);
    }
  }
}

}  // namespace spidar::sim
