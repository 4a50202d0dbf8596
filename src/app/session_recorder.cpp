#include "session_recorder.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli_support.hpp"

namespace spidar::app {
namespace {

namespace fs = std::filesystem;

/// Shortest text that reads back to the same double.
std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::ofstream open_csv(const fs::path& p) {
  std::ofstream f(p);
  if (!f) throw UsageError("--record: cannot write " + p.string());
  return f;
}

void sample_columns(std::ostream& os, const device::FingertipSample& s) {
  os << s.faults << ',' << s.consistent << ',' << s.finger_count;
  for (const auto& p : s.p_W)
    for (double v : p) os << ',' << num(v);
  for (const auto& f : s.f_W)
    for (double v : f) os << ',' << num(v);
}

std::string sample_header() {
  std::string h = "faults,consistent,finger_count";
  for (const char* what : {"p", "f"})
    for (int f = 0; f < device::kMaxFingers; ++f)
      for (const char* axis : {"x", "y", "z"}) h += std::string(",") + what + std::to_string(f) + axis;
  return h;
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

SessionRecorder::SessionRecorder(const std::string& dir, FrameStore store, const RecordingMeta& meta)
    : dir_(dir), store_(store), meta_(meta) {
  const fs::path d(dir);
  std::error_code ec;
  if (fs::exists(d / "session.json", ec))
    throw UsageError("--record " + dir + ": already holds a recording (session.json); choose a new folder");
  fs::create_directories(d, ec);
  if (ec) throw UsageError("--record " + dir + ": cannot create the folder: " + ec.message());
  if (store_ == FrameStore::kPng) fs::create_directories(d / "frames", ec);
  {
    std::ofstream cfg(d / "config.yaml");
    if (!cfg) throw UsageError("--record: cannot write " + (d / "config.yaml").string());
    cfg << meta.config_yaml;
  }
  nlohmann::json j;
  j["format"] = "spidar-mr recording";
  j["version"] = 1;
  j["width"] = meta.width;
  j["height"] = meta.height;
  j["fps"] = meta.fps;
  j["string_count"] = meta.string_count;
  j["finger_count"] = meta.finger_count;
  j["device"] = meta.device_name;
  j["frames"] = store_ == FrameStore::kPng ? "png" : "video";
  j["frames_codec"] = store_ == FrameStore::kPng ? "png" : store_ == FrameStore::kMjpg ? "avi/mjpg" : "mp4";
  for (int h = 0; h < 2; ++h)
    j["initial_r_W_hand"].push_back({meta.initial_r_W_hand[h].x(), meta.initial_r_W_hand[h].y(),
                                     meta.initial_r_W_hand[h].z()});
  {
    std::ofstream s(d / "session.json");
    if (!s) throw UsageError("--record: cannot write " + (d / "session.json").string());
    s << j.dump(2) << "\n";
  }
  device_csv_ = open_csv(d / "device.csv");
  device_csv_ << "seq,host_time_ns,device_time_us,status,repeats";
  for (int i = 0; i < meta.string_count; ++i) device_csv_ << ",count" << i;
  for (int i = 0; i < meta.string_count; ++i) device_csv_ << ",command" << i;
  device_csv_ << "\n";
  fingertip_csv_ = open_csv(d / "fingertips.csv");
  fingertip_csv_ << "t_ns,cycle," << sample_header() << "\n";
  frames_csv_ = open_csv(d / "frames.csv");
  frames_csv_ << "frame,t_exposure_ns,image," << sample_header() << "\n";
  scene_csv_ = open_csv(d / "scene.csv");
  scene_csv_ << "frame,shape,px,py,pz,qw,qx,qy,qz\n";
  fits_csv_ = open_csv(d / "fits.csv");
  fits_csv_ << "frame,hand,iterations,converged,cost_initial,cost_final,fingertip,wrist,joint_ball,"
               "silhouette,prior";
  for (int i = 0; i < hand::kParamCount; ++i) fits_csv_ << ",q" << i;
  fits_csv_ << "\n";
  if (store_ != FrameStore::kPng) {
    const render::VideoFormat mjpg = render::VideoFormat::kAviMjpg;
    auto v = render::VideoOutput::open((d / "camera.mp4").string(), meta.width, meta.height, meta.fps,
                                       store_ == FrameStore::kMjpg ? &mjpg : nullptr);
    if (!v) throw UsageError("--record: " + v.error().message);
    video_ = std::move(v).value();
  }
  dev_buf_.resize(RecordingDevice::kRing);
  sample_buf_.resize(1024);
}

SessionRecorder::~SessionRecorder() { stop(); }

void SessionRecorder::start(const RecordingDevice* device, const device::ServoLoop* servo) {
  device_ = device;
  servo_ = servo;
  thread_ = std::thread([this] { run(); });
}

void SessionRecorder::add_frame(FrameRecord frame) {
  std::unique_lock lock(mutex_);
  cv_.wait(lock, [&] { return queue_.size() < 16 || stop_; });
  queue_.push_back(std::move(frame));
  cv_.notify_all();
}

void SessionRecorder::run() {
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
}

void SessionRecorder::drain() {
  if (device_ != nullptr) {
    const std::size_t n = device_->ring().newest(dev_buf_.data(), dev_buf_.size());
    for (std::size_t k = n; k-- > 0;) {
      const DeviceCycleRecord& r = dev_buf_[k];
      if (r.seq <= last_dev_seq_) continue;
      if (r.seq != last_dev_seq_ + 1) lost_ += r.seq - last_dev_seq_ - 1;
      last_dev_seq_ = r.seq;
      device_csv_ << r.seq << ',' << r.reading.host_time_ns << ',' << r.reading.device_time_us << ','
                  << r.reading.status_flags << ',' << r.reading.repeats;
      for (int i = 0; i < meta_.string_count; ++i) device_csv_ << ',' << r.reading.counts[i];
      for (int i = 0; i < meta_.string_count; ++i) device_csv_ << ',' << (i < r.command_count ? r.commands[i] : 0);
      device_csv_ << '\n';
      ++device_written_;
    }
  }
  if (servo_ != nullptr) {
    const std::size_t n = servo_->newest_samples(sample_buf_.data(), sample_buf_.size());
    for (std::size_t k = n; k-- > 0;) {
      const device::FingertipSample& s = sample_buf_[k];
      if (have_cycle_ && s.cycle <= last_cycle_) continue;
      if (have_cycle_ && s.cycle != last_cycle_ + 1) lost_ += s.cycle - last_cycle_ - 1;
      have_cycle_ = true;
      last_cycle_ = s.cycle;
      fingertip_csv_ << s.t_ns << ',' << s.cycle << ',';
      sample_columns(fingertip_csv_, s);
      fingertip_csv_ << '\n';
      ++samples_written_;
    }
  }
}

void SessionRecorder::write_frame(FrameRecord& f) {
  std::string image;
  if (store_ == FrameStore::kPng) {
    char name[32];
    std::snprintf(name, sizeof name, "frames/%06lld.png", static_cast<long long>(f.index));
    image = name;
    if (auto st = render::write_png((fs::path(dir_) / image).string(), f.bgr); !st && error_.empty())
      error_ = st.error().message;
  } else {
    image = std::to_string(video_->frames());  // frame number in camera.mp4
    if (auto st = video_->write(f.bgr); !st && error_.empty()) error_ = st.error().message;
  }
  frames_csv_ << f.index << ',' << f.t_exposure_ns << ',' << image << ',';
  sample_columns(frames_csv_, f.measured);
  frames_csv_ << '\n';
  for (std::size_t i = 0; i < f.scene_poses.size(); ++i) {
    const Pose& X = f.scene_poses[i];
    scene_csv_ << f.index << ',' << i << ',' << num(X.p.x()) << ',' << num(X.p.y()) << ','
               << num(X.p.z()) << ',' << num(X.R.w()) << ',' << num(X.R.x()) << ',' << num(X.R.y())
               << ',' << num(X.R.z()) << '\n';
  }
  for (int h = 0; h < 2; ++h) {
    const auto& r = f.fits[h];
    fits_csv_ << f.index << ',' << h << ',' << r.iterations << ',' << (r.converged ? 1 : 0) << ','
              << num(r.cost_initial) << ',' << num(r.cost_final) << ',' << num(r.terms.fingertip) << ','
              << num(r.terms.wrist) << ',' << num(r.terms.joint_ball) << ',' << num(r.terms.silhouette)
              << ',' << num(r.terms.prior);
    for (int i = 0; i < hand::kParamCount; ++i) fits_csv_ << ',' << num(f.hands[h].q[i]);
    fits_csv_ << '\n';
  }
  ++frames_written_;
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
  for (std::ofstream* f : {&device_csv_, &fingertip_csv_, &frames_csv_, &scene_csv_, &fits_csv_}) {
    f->flush();
    if (!*f && error_.empty()) error_ = "writing the recording in " + dir_ + " failed (disk full?)";
    f->close();
  }
}

}  // namespace spidar::app
