#include "spidar/session/recording_writer.hpp"

#include "spidar/core/file_read.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "checked_file.hpp"
#include "spidar/core/atomic_write.hpp"
#include "spidar/session/json_text.hpp"

namespace spidar::session {
namespace {

namespace fs = std::filesystem;
namespace files = recording_files;

namespace bounds = recording_bounds;

/// `v` saturated to [-bound, bound] (a solve from a glitched reading may land anywhere; the
/// recording keeps it readable), as text.
std::string bounded_text(double v, double bound) { return number_text(std::clamp(v, -bound, bound)); }

void append_sample(std::string& row, const device::FingertipSample& s) {
  row += std::to_string(s.faults) + ',' + std::to_string(s.consistent) + ',' + std::to_string(s.finger_count);
  for (const auto& p : s.p_W)
    for (double v : p) row += ',' + bounded_text(v, bounds::kPosition_m);
  for (const auto& f : s.f_W)
    for (double v : f) row += ',' + bounded_text(v, bounds::kForce_N);
}

std::unique_ptr<CheckedFile> open_csv(const fs::path& dir, std::string_view name,
                                      const std::vector<std::string>& columns) {
  auto f = std::make_unique<CheckedFile>((dir / name).string());
  f->write(header_row(columns) + "\n");
  return f;
}

}  // namespace

std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::string device_row_text(const DeviceCycleRecord& r, int string_count) {
  std::string row = std::to_string(r.seq) + ',' + std::to_string(r.reading.host_time_ns) + ',' +
                    std::to_string(r.reading.device_time_us) + ',' + std::to_string(r.reading.status_flags) +
                    ',' + std::to_string(r.reading.repeats);
  for (int i = 0; i < string_count; ++i) row += ',' + std::to_string(r.reading.counts[i]);
  for (int i = 0; i < string_count; ++i) row += ',' + std::to_string(i < r.command_count ? r.commands[i] : 0);
  return row + '\n';
}

std::string fingertip_row_text(const device::FingertipSample& s, int string_count) {
  std::string row = std::to_string(s.t_ns) + ',' + std::to_string(s.cycle) + ',';
  append_sample(row, s);
  for (int i = 0; i < string_count; ++i)
    row += ',' + bounded_text(i < s.string_count ? s.tension[i] : 0.0, bounds::kForce_N);
  for (int i = 0; i < string_count; ++i) row += ',' + std::to_string(i < s.string_count ? s.command[i] : 0);
  return row + '\n';
}

std::string frame_row_text(const FrameRow& f) {
  std::string row = std::to_string(f.index) + ',' + std::to_string(f.t_exposure_ns) + ',' + f.image + ',';
  append_sample(row, f.measured);
  return row + '\n';
}

std::string scene_row_text(std::int64_t frame, std::size_t shape, const Pose& X) {
  std::string row = std::to_string(frame) + ',' + std::to_string(shape);
  for (double v : {X.p.x(), X.p.y(), X.p.z()}) row += ',' + bounded_text(v, bounds::kPosition_m);
  for (double v : {X.R.w(), X.R.x(), X.R.y(), X.R.z()}) row += ',' + number_text(v);
  return row + '\n';
}

std::string fit_row_text(const FitRow& r) {
  // A fit with a NaN or infinity, or beyond the recording's bounds (a diverged fit), is marked
  // finite = 0 and its numbers left empty: the reader refuses "nan" or 1e300 as damage.
  auto cost_ok = [](double c) { return std::isfinite(c) && c >= 0.0 && c <= bounds::kCost; };
  bool finite = r.finite && cost_ok(r.cost_initial) && cost_ok(r.cost_final);
  for (double v : r.terms) finite = finite && cost_ok(v);
  for (double v : r.q) finite = finite && std::isfinite(v) && std::abs(v) <= bounds::kPoseParameter;
  std::string row = std::to_string(r.frame) + ',' + std::to_string(r.hand) + ',' + std::to_string(r.iterations) +
                    ',' + (r.converged ? "1" : "0") + ',' + (finite ? "1" : "0");
  auto add = [&](double v) { row += ',' + (finite ? number_text(v) : std::string()); };
  add(r.cost_initial);
  add(r.cost_final);
  for (double v : r.terms) add(v);
  for (double v : r.q) add(v);
  // The model's sizes are the fit's input, not its result: written even when the fit was not
  // finite; 0 when unknown (not a size in (0, 1) m).
  for (double v : {r.length_m, r.width_m}) row += ',' + (v > 0.0 && v < 1.0 ? number_text(v) : std::string("0"));
  return row + '\n';
}

namespace {

/// SpidarError if the folder `dir` holds a recording (its session.json).
void refuse_a_recording_in(const std::string& dir) {
  std::error_code ec;
  if (fs::exists(fs::path(dir) / files::kSession, ec))
    throw SpidarError("--record " + dir + ": already holds a recording (session.json); choose a new folder");
}

}  // namespace

void check_new_recording_folder(const std::string& dir) {
  const fs::path d(dir);
  std::error_code ec;
  if (!fs::exists(d, ec)) return;
  refuse_a_recording_in(dir);
  if (!fs::is_directory(d, ec)) throw SpidarError("--record " + dir + ": exists and is not a folder; choose a new folder");
  if (fs::is_empty(d, ec) && !ec) return;
  std::string held = ec ? "cannot list it: " + ec.message() : "it holds files";
  for (fs::directory_iterator it(d, ec); !ec && it != fs::directory_iterator(); ++it) {
    held = "it holds " + core::printable_for_message(it->path().filename().string());
    break;
  }
  throw SpidarError("--record " + dir + ": is not empty (" + held + "); a recording goes into a new or empty folder");
}

RecordingWriter::RecordingWriter(std::string dir, const RecordingMeta& meta, std::string_view config_yaml)
    : dir_(std::move(dir)), meta_(meta) {
  if (meta_.string_count < 1 || meta_.string_count > device::kMaxDeviceStrings)
    throw SpidarError("recording " + dir_ + ": string_count " + std::to_string(meta_.string_count) +
                      " is outside 1.." + std::to_string(device::kMaxDeviceStrings));
  refuse_a_recording_in(dir_);
  const fs::path d(dir_);
  std::error_code ec;
  fs::create_directories(d, ec);
  if (ec) throw core::FileError(dir_, "cannot create the folder: " + ec.message());
  if (meta_.store == FrameStore::kPng) {
    fs::create_directories(d / files::kFramesDir, ec);
    if (ec) throw core::FileError((d / files::kFramesDir).string(), "cannot create the folder: " + ec.message());
    if (meta_.frames_file.empty()) meta_.frames_file = std::string(files::kFramesDir);
  }
  core::write_file_atomic((d / files::kConfig).string(), config_yaml);
  write_session_json(false);
  device_ = open_csv(d, files::kDevice, device_columns(meta_.string_count));
  std::vector<std::string> fingertip_header = fingertip_columns();
  for (auto& c : servo_output_columns(meta_.string_count)) fingertip_header.push_back(std::move(c));
  fingertips_ = open_csv(d, files::kFingertips, fingertip_header);
  frames_ = open_csv(d, files::kFrames, frame_columns());
  scene_ = open_csv(d, files::kScene, scene_columns());
  std::vector<std::string> fit_header = fit_columns();
  for (auto& c : fit_size_columns()) fit_header.push_back(std::move(c));
  fits_ = open_csv(d, files::kFits, fit_header);
}

RecordingWriter::~RecordingWriter() = default;

void RecordingWriter::write_session_json(bool complete) const {
  nlohmann::json j;
  j["format"] = kRecordingFormat;
  j["version"] = kRecordingVersion;
  j["width"] = meta_.width;
  j["height"] = meta_.height;
  j["fps"] = meta_.fps;
  j["string_count"] = meta_.string_count;
  j["finger_count"] = meta_.finger_count;
  j["device"] = meta_.device_name;
  j["frames"] = frame_store_name(meta_.store);
  j["frames_file"] = meta_.frames_file;
  j["frames_codec"] = meta_.frames_codec;
  for (int h = 0; h < 2; ++h) {
    const Vec3& r = meta_.initial_r_W_hand[h];
    j["initial_r_W_hand"].push_back({r.x(), r.y(), r.z()});
  }
  j["complete"] = complete;
  if (complete) {
    j["rows"] = {{"device", counts_.device}, {"fingertips", counts_.fingertips}, {"frames", counts_.frames},
                 {"scene", counts_.scene},   {"fits", counts_.fits}};
    j["seconds"] = counts_.seconds;
  }
  core::write_file_atomic((fs::path(dir_) / files::kSession).string(), json_text(j, 2) + "\n");
}

void RecordingWriter::set_frames_file(const std::string& file, const std::string& codec) {
  meta_.frames_file = file;
  meta_.frames_codec = codec;
  write_session_json(false);
}

bool RecordingWriter::write_device(const DeviceCycleRecord& r) {
  if (!device_->write(device_row_text(r, meta_.string_count))) return false;
  ++counts_.device;
  return true;
}

bool RecordingWriter::write_fingertip(const device::FingertipSample& s) {
  if (!fingertips_->write(fingertip_row_text(s, meta_.string_count))) return false;
  if (counts_.fingertips == 0) t_first_ns_ = s.t_ns;
  t_last_ns_ = s.t_ns;
  ++counts_.fingertips;
  return true;
}

bool RecordingWriter::write_frame(const FrameRow& frame, std::span<const Pose> scene,
                                  const std::array<FitRow, 2>& fits) {
  if (!frames_->write(frame_row_text(frame))) return false;
  if (counts_.frames == 0) frame_first_ns_ = frame.t_exposure_ns;
  frame_last_ns_ = frame.t_exposure_ns;
  ++counts_.frames;
  for (std::size_t i = 0; i < scene.size(); ++i) {
    if (!scene_->write(scene_row_text(frame.index, i, scene[i]))) return false;
    ++counts_.scene;
  }
  for (const FitRow& r : fits) {
    if (!fits_->write(fit_row_text(r))) return false;
    ++counts_.fits;
  }
  return true;
}

std::string RecordingWriter::error() const {
  for (const auto* f : {device_.get(), fingertips_.get(), frames_.get(), scene_.get(), fits_.get()})
    if (f != nullptr && !f->ok()) return f->error();
  return "";
}

void RecordingWriter::close_incomplete() {
  for (auto* f : {device_.get(), fingertips_.get(), frames_.get(), scene_.get(), fits_.get()}) {
    try {
      f->close();
    } catch (const core::FileError&) {  // error() keeps it
    }
  }
}

void RecordingWriter::finish() {
  if (finished_) return;
  // Every file is closed (so none stays open), the first failure is thrown.
  std::string first;
  for (auto* f : {device_.get(), fingertips_.get(), frames_.get(), scene_.get(), fits_.get()}) {
    try {
      f->close();
    } catch (const core::FileError& e) {
      if (first.empty()) first = e.what();
    }
  }
  if (!first.empty()) throw SpidarError(first + " (the recording is incomplete: it has no completion marker)");
  const std::int64_t span_ns = counts_.fingertips > 1 ? t_last_ns_ - t_first_ns_ : frame_last_ns_ - frame_first_ns_;
  counts_.seconds = static_cast<double>(span_ns) * 1e-9;
  write_session_json(true);
  finished_ = true;
}

}  // namespace spidar::session
