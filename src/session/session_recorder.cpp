#include "spidar/session/session_recorder.hpp"
#include "spidar/core/thread_name.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>

namespace spidar::session {
namespace {

namespace fs = std::filesystem;

RecordingMeta schema_meta(const RecorderSetup& m, FrameStore store) {
  RecordingMeta s;
  s.width = m.width;
  s.height = m.height;
  s.fps = m.fps;
  s.string_count = m.string_count;
  s.finger_count = m.finger_count;
  s.device_name = m.device_name;
  s.store = store;
  s.frames_codec = store == FrameStore::kPng ? "png" : "";
  s.initial_r_W_hand = m.initial_r_W_hand;
  return s;
}

FitRow fit_row(std::int64_t frame, int hand, const registration::FitReport& r, const hand::HandParams& p,
               const hand::HandDimensions& sizes) {
  FitRow row;
  row.frame = frame;
  row.hand = hand;
  row.iterations = r.iterations;
  row.converged = r.converged;
  row.cost_initial = r.cost_initial;
  row.cost_final = r.cost_final;
  row.terms = {r.terms.fingertip, r.terms.wrist, r.terms.joint_ball, r.terms.silhouette, r.terms.prior};
  for (int i = 0; i < hand::kPaperParamCount; ++i) row.q[static_cast<std::size_t>(i)] = p.q[i];
  row.length_m = sizes.length;
  row.width_m = sizes.width;
  return row;  // the writer marks a row with a NaN or infinity as not finite
}

}  // namespace

Status RecordingDevice::read(device::EncoderReading& out) {
  Status st = inner_.read(out);
  if (st) pending_.reading = out;
  return st;
}

Status RecordingDevice::write(std::span<const std::int32_t> commands) {
  Status st = inner_.write(commands);
  pending_.seq = ++seq_;
  pending_.command_count = static_cast<int>(std::min<std::size_t>(commands.size(), device::kMaxDeviceStrings));
  for (int i = 0; i < pending_.command_count; ++i) pending_.commands[i] = commands[i];
  ring_->push(pending_);
  return st;
}

SessionRecorder::SessionRecorder(const std::string& dir, FrameStore store, const RecorderSetup& meta,
                                 const RecordingDevice& device, const device::ServoLoop& servo)
    : dir_(dir), store_(store), meta_(meta), device_(&device), servo_(&servo) {
  check_new_recording_folder(dir);
  writer_ = std::make_unique<RecordingWriter>(dir, schema_meta(meta, store), meta.config_yaml);
  if (store_ != FrameStore::kPng) {
    const render::VideoFormat mjpg = render::VideoFormat::kAviMjpg;
    auto v = render::VideoOutput::open((fs::path(dir) / "camera.mp4").string(), meta.width, meta.height, meta.fps,
                                       store_ == FrameStore::kMjpg ? &mjpg : nullptr);
    if (!v) throw SpidarError("--record: " + v.error().message);
    video_ = std::move(v).value();
    // The format decides the extension (camera.mp4 or camera.avi): session.json names the file.
    writer_->set_frames_file(fs::path(video_->path()).filename().string(),
                             render::video_format_name(video_->format()));
  }
  dev_buf_.resize(RecordingDevice::kRing);
  sample_buf_.resize(1024);
}

SessionRecorder::~SessionRecorder() { stop(); }

void SessionRecorder::on_start() { thread_ = std::thread([this] { run(); }); }

void SessionRecorder::on_frame(const FrameEvent& e) {
  FrameRecord fr;
  fr.index = static_cast<std::int64_t>(e.index);
  fr.t_exposure_ns = e.t_exposure_ns;
  // The sensor's frame (through the lens, if any): a replay undistorts it as the session did.
  // Cloned: written by the writer thread, after the source reused it.
  fr.bgr = (e.sensor_bgr != nullptr ? e.sensor_bgr : e.bgr)->clone();
  fr.measured = *e.measured;
  fr.scene_poses.reserve(e.scene->shapes.size());
  for (const Shape& sh : e.scene->shapes) fr.scene_poses.push_back(sh.X_WS);
  fr.hands = e.result->hands;
  fr.fits = e.result->fits;
  for (int h = 0; h < 2; ++h) fr.sizes[h] = e.result->models[h].shape.dimensions;
  add_frame(std::move(fr));
}

void SessionRecorder::on_end(const SessionSummary& /*s*/) { stop(); }

void SessionRecorder::add_frame(FrameRecord frame) {
  std::unique_lock lock(mutex_);
  cv_.wait(lock, [&] { return queue_.size() < 16 || stop_; });
  queue_.push_back(std::move(frame));
  cv_.notify_all();
}

void SessionRecorder::note_error(const std::string& e) {
  if (error_.empty()) error_ = e;
}

void SessionRecorder::run() {
  core::set_thread_name("spidar-record");
  try {
    for (;;) {
      std::deque<FrameRecord> frames;
      bool stopping = false;
      {
        std::unique_lock lock(mutex_);
        cv_.wait_for(lock, std::chrono::milliseconds(10), [&] { return stop_ || !queue_.empty(); });
        frames.swap(queue_);
        stopping = stop_;
        cv_.notify_all();
      }
      drain();
      for (FrameRecord& f : frames) write_frame(f);
      if (stopping) {
        std::lock_guard lock(mutex_);
        if (queue_.empty()) break;
      }
    }
    drain();
  } catch (const std::exception& e) {
    note_error(e.what());
  }
}

void SessionRecorder::drain() {
  if (device_ != nullptr) {
    // Only back to the last record written (the ring holds 4096: copied whole every 10 ms it
    // cost more than the writing).
    const RecordingDevice::Ring& ring = device_->ring();
    const std::uint64_t last_seq = last_dev_seq_;
    const std::size_t n = core::read_newest_until(
        [&ring](DeviceCycleRecord* out, std::size_t max) { return ring.newest(out, max); }, std::span(dev_buf_),
        [last_seq](const DeviceCycleRecord& r) { return r.seq <= last_seq; });
    for (std::size_t k = n; k-- > 0;) {
      const DeviceCycleRecord& r = dev_buf_[k];
      if (r.seq <= last_dev_seq_) continue;
      if (r.seq != last_dev_seq_ + 1) lost_ += r.seq - last_dev_seq_ - 1;
      last_dev_seq_ = r.seq;
      if (writer_->write_device(r)) ++device_written_;
    }
  }
  if (servo_ != nullptr) {
    const device::ServoLoop& servo = *servo_;
    const bool have = have_cycle_;
    const std::uint64_t last_cycle = last_cycle_;
    const std::size_t n = core::read_newest_until(
        [&servo](device::FingertipSample* out, std::size_t max) { return servo.newest_samples(out, max); },
        std::span(sample_buf_), [have, last_cycle](const device::FingertipSample& x) { return have && x.cycle <= last_cycle; });
    for (std::size_t k = n; k-- > 0;) {
      const device::FingertipSample& s = sample_buf_[k];
      if (have_cycle_ && s.cycle <= last_cycle_) continue;
      if (have_cycle_ && s.cycle != last_cycle_ + 1) lost_ += s.cycle - last_cycle_ - 1;
      have_cycle_ = true;
      last_cycle_ = s.cycle;
      if (writer_->write_fingertip(s)) ++samples_written_;
    }
  }
}

void SessionRecorder::write_frame(FrameRecord& f) {
  FrameRow row;
  row.index = f.index;
  row.t_exposure_ns = f.t_exposure_ns;
  row.measured = f.measured;
  if (store_ == FrameStore::kPng) {
    char name[32];
    std::snprintf(name, sizeof name, "frames/%06lld.png", static_cast<long long>(f.index));
    row.image = name;
    if (auto st = render::write_png((fs::path(dir_) / row.image).string(), f.bgr); !st) note_error(st.error().message);
  } else {
    row.image = std::to_string(video_->frames());  // frame number in the video
    if (auto st = video_->write(f.bgr); !st) note_error(st.error().message);
  }
  const std::array<FitRow, 2> fits = {fit_row(f.index, 0, f.fits[0], f.hands[0], f.sizes[0]),
                                      fit_row(f.index, 1, f.fits[1], f.hands[1], f.sizes[1])};
  if (writer_->write_frame(row, f.scene_poses, fits)) ++frames_written_;
}

void SessionRecorder::stop() {
  if (stopped_) return;
  stopped_ = true;
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
    cv_.notify_all();
  }
  if (thread_.joinable()) thread_.join();
  if (video_) video_->close();
  note_error(writer_->error());
  // The completion marker only when every file was written whole.
  if (!error_.empty()) {
    writer_->close_incomplete();
    return;
  }
  try {
    writer_->finish();
  } catch (const std::exception& e) {
    note_error(e.what());
  }
}

}  // namespace spidar::session
