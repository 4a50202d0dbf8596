#include "spidar/session/async_sinks.hpp"
#include "spidar/core/thread_name.hpp"

#include <algorithm>
#include <chrono>
#include <future>
#include <stdexcept>

#include "spidar/core/result.hpp"

#include "spidar/core/realtime.hpp"

namespace spidar::session {

AsyncSinks::AsyncSinks(std::vector<FrameSink*> sinks, int slots, int nice)
    : sinks_(std::move(sinks)), slots_(static_cast<std::size_t>(slots < 1 ? 1 : slots)),
      nice_(std::clamp(nice, -20, 19)) {
  for (std::size_t k = slots_.size(); k-- > 0;) free_.push_back(k);
}

AsyncSinks::~AsyncSinks() {
  {
    std::lock_guard lock(mutex_);
    quit_ = true;
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void AsyncSinks::compare(const vision::Camera& camera, const std::array<hand::HandModel, 2>& models,
                         const pipeline::FramePipelineParams& main,
                         std::optional<pipeline::WarmUpFrame> warm_up) {
  if (started_) throw std::logic_error("async sinks: compare after on_start");
  comparison_ = std::make_unique<Comparison>();
  comparison_->warm_up = std::move(warm_up);
  comparison_->camera = camera;
  comparison_->models = models;
  comparison_->params = pipeline::comparison_params(main);
}

void AsyncSinks::compose_others(const render::CompositorParams& main) {
  if (started_) throw std::logic_error("async sinks: compose_others after on_start");
  if (auto st = render::validate(main); !st) throw SpidarError("other composites: " + st.error().message);
  other_.emplace(pipeline::other_compositor_params(main));
}

void AsyncSinks::compose_other(Slot& slot) {
  FrameEvent& e = slot.e;
  if (!other_ || e.bgr == nullptr) return;
  const auto t0 = std::chrono::steady_clock::now();
  if (e.result != nullptr && e.result->other.empty() && !e.result->virt.colour.empty()) {
    pipeline::FrameResult* r = &slot.result;
    if (e.result != r) {  // held: shared, not ours to change
      slot.shown = *e.result;  // the images shared, not copied
      r = &slot.shown;
    }
    if (auto st = pipeline::compose_result(*other_, *r, *e.bgr, &slot.other, &slot.other_alpha); !st)
      throw SpidarError("other composite: " + st.error().message);
    r->other = slot.other;
    r->other_alpha = slot.other_alpha;
    e.result = r;
  }
  if (e.compared != nullptr && e.compared->other.empty() && !e.compared->virt.colour.empty()) {
    // Ours: the copy of the frame thread's comparison, or the one made here (compare).
    pipeline::FrameResult* c = e.compared == &slot.compared ? &slot.compared
                               : comparison_ && e.compared == &comparison_->result ? &comparison_->result
                                                                                   : nullptr;
    if (c == nullptr) throw std::logic_error("async sinks: a comparison neither copied nor made here");
    if (auto st = pipeline::compose_result(*other_, *c, *e.bgr, &c->other, &c->other_alpha); !st)
      throw SpidarError("other composite (comparison): " + st.error().message);
  }
  // Comparison work, as the comparison's pictures are (the report's truth_ms).
  e.compare_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

void AsyncSinks::start_comparison() {
  if (!comparison_) return;
  auto ctx = render::Context::create_headless();
  if (!ctx) throw SpidarError("comparison: OpenGL: " + ctx.error().message);
  comparison_->context = std::move(ctx).value();
  auto pipe = pipeline::FramePipeline::create(*comparison_->context, comparison_->camera, comparison_->models,
                                              comparison_->params);
  if (!pipe) throw SpidarError("comparison: " + pipe.error().message);
  comparison_->pipeline = std::move(pipe).value();
  if (comparison_->warm_up) {
    if (auto st = pipeline::warm_up(*comparison_->pipeline, *comparison_->warm_up); !st)
      throw SpidarError("comparison: " + st.error().message);
    comparison_->warm_up.reset();
  }
}

void AsyncSinks::make_comparison(Slot& slot) {
  FrameEvent& e = slot.e;
  if (e.compare_pending == PendingComparison::kNone) return;
  if (!comparison_ || !comparison_->pipeline)
    throw SpidarError("comparison: a frame's comparison was left pending but nobody makes it "
                      "(AsyncSinks::compare)");
  if (e.bgr == nullptr || e.measured == nullptr || e.scene == nullptr || e.result == nullptr)
    throw SpidarError("comparison: a frame left pending without its image, fingertips, scene or result");
  const auto t0 = std::chrono::steady_clock::now();
  if (auto st = comparison_->context->make_current(); !st) throw SpidarError("comparison: " + st.error().message);
  const bool picture = e.compare_pending == PendingComparison::kFitAndPicture;
  if (auto st = pipeline::process_comparison(*comparison_->pipeline, *e.result, *e.bgr, *e.measured, *e.scene,
                                             picture, &comparison_->result);
      !st)
    throw SpidarError("comparison: " + st.error().message);
  if (picture) e.compared = &comparison_->result;
  e.compare_pending = PendingComparison::kNone;
  e.compare_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

void AsyncSinks::on_start() {
  if (started_) return;
  started_ = true;
  std::promise<void> ready;
  auto started = ready.get_future();
  thread_ = std::thread([this, &ready] {
    core::set_thread_name("spidar-output");
    if (nice_ != 0) (void)core::set_nice(nice_);  // best effort: a normal share otherwise
    try {
      start_comparison();
      for (FrameSink* k : sinks_) k->on_start();
    } catch (...) {
      if (comparison_) {  // its GL objects go on this thread, with their context
        comparison_->pipeline.reset();
        comparison_->context.reset();
      }
      ready.set_exception(std::current_exception());
      return;
    }
    ready.set_value();
    run();
  });
  try {
    started.get();
  } catch (...) {
    thread_.join();
    throw;
  }
}

void AsyncSinks::rethrow_if_failed() {
  if (!error_) return;
  std::exception_ptr e = error_;
  error_ = nullptr;  // once
  std::rethrow_exception(e);
}

void AsyncSinks::copy_into(const FrameEvent& from, Slot& to) const {
  to.e = from;
  if (from.bgr != nullptr && from.filmed_hold && from.bgr->data == from.filmed_hold->frame.bgr.data &&
      from.bgr->size() == from.filmed_hold->frame.bgr.size()) {
    to.e.bgr = &from.filmed_hold->frame.bgr;  // the held filmed frame's own image
  } else if (from.bgr != nullptr) {
    from.bgr->copyTo(to.bgr);
    to.e.bgr = &to.bgr;
  }
  if (from.sensor_bgr == from.bgr) {
    to.e.sensor_bgr = to.e.bgr;
  } else if (from.sensor_bgr != nullptr) {  // through a lens
    from.sensor_bgr->copyTo(to.sensor_bgr);
    to.e.sensor_bgr = &to.sensor_bgr;
  }
  if (from.measured != nullptr) {
    to.measured = *from.measured;
    to.e.measured = &to.measured;
  }
  if (from.scene != nullptr) {
    to.scene = *from.scene;  // shapes by value; the meshes are shared and not changed per frame
    to.e.scene = &to.scene;
  }
  if (from.result_hold) {
    to.e.result = from.result_hold.get();  // held by to.e.result_hold until the sinks are done
  } else if (from.result != nullptr) {
    pipeline::copy_frame_result(*from.result, &to.result);
    to.e.result = &to.result;
  }
  if (from.compared != nullptr) {
    pipeline::copy_frame_result(*from.compared, &to.compared);
    to.e.compared = &to.compared;
  }
  if (from.filmed_hold) {
    to.e.filmed = from.filmed_hold.get();  // held by to.e.filmed_hold until the sinks are done
  } else if (from.filmed != nullptr) {
    sim::copy_filmed_frame(*from.filmed, &to.filmed);
    to.e.filmed = &to.filmed;
  }
}

void AsyncSinks::on_frame(const FrameEvent& e) {
  if (!started_) on_start();
  std::size_t k = 0;
  {
    std::unique_lock lock(mutex_);
    rethrow_if_failed();
    if (free_.empty()) {
      const auto t0 = std::chrono::steady_clock::now();
      changed_.wait(lock, [this] { return !free_.empty() || error_ || !thread_.joinable(); });
      ++waits_;
      waited_ms_ += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      rethrow_if_failed();
      if (free_.empty()) throw std::logic_error("async sinks: the output thread is gone");
    }
    k = free_.back();
    free_.pop_back();
  }
  copy_into(e, slots_[k]);  // the slot is this thread's until queued
  {
    std::lock_guard lock(mutex_);
    queued_.push_back(k);
  }
  changed_.notify_all();
}

void AsyncSinks::run() {
  // However the thread ends, the comparison's GL objects go with their context on this thread.
  struct ReleaseComparison {
    Comparison* p;
    ~ReleaseComparison() {
      if (p == nullptr) return;
      if (p->context) (void)p->context->make_current();
      p->pipeline.reset();
      p->context.reset();
    }
  } release{comparison_.get()};
  for (;;) {
    std::size_t k = 0;
    {
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [this] { return quit_ || !queued_.empty() || summary_.has_value(); });
      if (quit_) return;
      if (queued_.empty()) break;  // ending, everything delivered
      k = queued_.front();
      queued_.pop_front();
    }
    bool failed = false;
    try {
      make_comparison(slots_[k]);
      compose_other(slots_[k]);
      for (FrameSink* sink : sinks_) sink->on_frame(slots_[k].e);
    } catch (...) {
      std::lock_guard lock(mutex_);
      error_ = std::current_exception();
      failed = true;
    }
    // No view of the held result's images may outlive the hold: the pipeline refills them (the
    // comparison shares its matte).
    slots_[k].shown = pipeline::FrameResult{};
    if (comparison_) comparison_->result.key = vision::ChromaKeyResult{};
    slots_[k].e.result_hold.reset();  // back to their pools, unless a sink kept them
    slots_[k].e.filmed_hold.reset();
    {
      std::lock_guard lock(mutex_);
      free_.push_back(k);
    }
    changed_.notify_all();
    if (failed) return;  // the frame thread re-throws; no more frames, no on_end
  }
  // on_end, on this thread.
  SessionSummary s;
  {
    std::lock_guard lock(mutex_);
    s = *summary_;
  }
  try {
    for (FrameSink* k : sinks_) k->on_end(s);
  } catch (...) {
    std::lock_guard lock(mutex_);
    error_ = std::current_exception();
  }
}

void AsyncSinks::on_end(const SessionSummary& s) {
  if (!thread_.joinable()) {
    std::lock_guard lock(mutex_);
    rethrow_if_failed();
    return;
  }
  {
    std::lock_guard lock(mutex_);
    summary_ = s;
  }
  changed_.notify_all();
  thread_.join();
  std::lock_guard lock(mutex_);
  rethrow_if_failed();
}

std::uint64_t AsyncSinks::waits() const {
  std::lock_guard lock(mutex_);
  return waits_;
}

double AsyncSinks::waited_ms() const {
  std::lock_guard lock(mutex_);
  return waited_ms_;
}

}  // namespace spidar::session
