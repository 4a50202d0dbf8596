#pragma once
// A small recording written by RecordingWriter into a temporary folder, for the reader's tests.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "spidar/session/recording_writer.hpp"

namespace spidar::session::testing {

namespace fs = std::filesystem;

inline std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}
inline void spit(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

/// The lines of a text file (without their '\n').
inline std::vector<std::string> lines_of(const fs::path& p) {
  std::vector<std::string> out;
  std::ifstream f(p, std::ios::binary);
  for (std::string l; std::getline(f, l);) out.push_back(l);
  return out;
}
inline void write_lines(const fs::path& p, const std::vector<std::string>& lines) {
  std::string text;
  for (const auto& l : lines) text += l + "\n";
  spit(p, text);
}
/// 1-based character column where field `field` (0-based) of `line` starts.
inline int column_of(const std::string& line, int field) {
  std::size_t at = 0;
  for (int k = 0; k < field; ++k) at = line.find(',', at) + 1;
  return static_cast<int>(at) + 1;
}
/// Replaces field `field` (0-based) of line `line_no` (1-based) of the CSV `p`; returns the
/// column where it starts.
inline int set_field(const fs::path& p, int line_no, int field, const std::string& value) {
  auto lines = lines_of(p);
  std::string& l = lines.at(static_cast<std::size_t>(line_no - 1));
  const int col = column_of(l, field);
  const std::size_t start = static_cast<std::size_t>(col - 1);
  const std::size_t end = l.find(',', start);
  l.replace(start, end == std::string::npos ? std::string::npos : end - start, value);
  write_lines(p, lines);
  return col;
}

/// A fresh folder under the test temp dir, removed at the end.
class TempFolder {
 public:
  explicit TempFolder(const std::string& name)
      : path_(fs::path(::testing::TempDir()) / ("spidar_session_" + name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempFolder() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

/// What the test recording holds: 3 strings, 2 fingers, 5 frames of 2 shapes, 20 servo cycles.
struct TestRecording {
  RecordingMeta meta;
  std::vector<DeviceCycleRecord> device;
  std::vector<device::FingertipSample> fingertips;
  std::vector<FrameRow> frames;
  std::vector<std::vector<Pose>> scene;
  std::vector<std::array<FitRow, 2>> fits;
};

inline TestRecording make_test_recording(FrameStore store) {
  TestRecording t;
  t.meta.width = 64;
  t.meta.height = 48;
  t.meta.fps = 25;
  t.meta.string_count = 3;
  t.meta.finger_count = 2;
  t.meta.device_name = "test device";
  t.meta.store = store;
  t.meta.frames_codec = store == FrameStore::kPng ? "png" : "avi/mjpg";
  t.meta.initial_r_W_hand = {Vec3(0.1, -0.2, 0.3), Vec3(-0.1, 0.2, 1.0 / 3.0)};
  const std::int64_t t0 = 123'456'789'000;
  for (int k = 0; k < 20; ++k) {
    DeviceCycleRecord r;
    r.seq = static_cast<std::uint64_t>(k + 1 + (k >= 10 ? 1 : 0));  // a lost row: a gap
    r.reading.host_time_ns = t0 + std::int64_t{k} * 125'000'000;  // 8 Hz: 2.375 s in all
    r.reading.device_time_us = 4294967000u + static_cast<std::uint32_t>(k * 1000);  // wraps
    r.reading.status_flags = k == 7 ? 4u : 0u;
    r.reading.repeats = k == 8 ? 1u : 0u;
    r.reading.string_count = 3;
    r.command_count = 3;
    for (int i = 0; i < 3; ++i) {
      r.reading.counts[i] = -70000 + 1234 * k + i;
      r.commands[i] = 100 * i - k;
    }
    t.device.push_back(r);
    device::FingertipSample s;
    s.t_ns = r.reading.host_time_ns;
    s.cycle = static_cast<std::uint64_t>(1000 + k);
    s.faults = 0;
    s.consistent = 3;
    s.finger_count = 2;
    for (int f = 0; f < 2; ++f)
      for (int a = 0; a < 3; ++a) {
        s.p_W[f][a] = 0.1 * f - 0.01 * a + 1e-3 * k + 1.0 / 7.0;
        s.f_W[f][a] = a == 2 ? -0.5 * k : 1e-17 * f;
      }
    s.string_count = 3;  // the servo's outputs: tensions [N] and motor commands [DAC counts]
    for (int i = 0; i < 3; ++i) {
      s.tension[static_cast<std::size_t>(i)] = 1.0 / 3.0 + k + 0.1 * i;
      s.command[static_cast<std::size_t>(i)] = 200 * i - k;
    }
    t.fingertips.push_back(s);
  }
  for (int i = 0; i < 5; ++i) {
    FrameRow f;
    f.index = i;
    f.t_exposure_ns = t0 + 250'000'000 + std::int64_t{i} * 375'000'000;
    char name[32];
    std::snprintf(name, sizeof name, "frames/%06d.png", i);
    f.image = store == FrameStore::kPng ? name : std::to_string(i);
    f.measured = t.fingertips[static_cast<std::size_t>(2 + 3 * i)];
    f.measured.t_ns = f.t_exposure_ns;
    f.measured.cycle = 0;
    t.frames.push_back(f);
    std::vector<Pose> poses(2);
    poses[1].p = Vec3(0.01 * i, -0.2, 0.3);
    poses[1].R = Quat(Eigen::AngleAxisd(0.1 * i, Vec3(1, 2, 3).normalized()));
    t.scene.push_back(poses);
    std::array<FitRow, 2> fits;
    for (int h = 0; h < 2; ++h) {
      FitRow& r = fits[static_cast<std::size_t>(h)];
      r.frame = i;
      r.hand = h;
      r.iterations = 3 + i;
      r.converged = h == 0;
      r.cost_initial = 10.0 / (i + 1);
      r.cost_final = 1.0 / 3.0 / (i + 1);
      for (std::size_t k = 0; k < r.terms.size(); ++k) r.terms[k] = 0.1 * static_cast<double>(k) + h;
      for (std::size_t k = 0; k < r.q.size(); ++k) r.q[k] = std::sin(static_cast<double>(k + i + h));
      r.length_m = 0.19 + 0.001 * i + 0.01 / 3.0 * h;  // a personalised size moving per frame
      r.width_m = 0.085 - 0.0005 * i;
    }
    if (i == 3) {  // a live fit that diverged: written as finite = 0
      fits[1].finite = false;
      fits[1].q[4] = std::nan("");
    }
    t.fits.push_back(fits);
  }
  return t;
}

/// Writes `t` into `dir` with RecordingWriter (PNG files: a few bytes each, the reader checks
/// only that they exist; video: an empty camera.avi).
inline void write_test_recording(const TestRecording& t, const fs::path& dir) {
  RecordingWriter w(dir.string(), t.meta, "device_config: x.yaml\n");
  if (t.meta.store != FrameStore::kPng) {
    spit(dir / "camera.avi", "not really a video");
    w.set_frames_file("camera.avi", "avi/mjpg");
  }
  for (std::size_t k = 0; k < t.device.size(); ++k) {
    ASSERT_TRUE(w.write_device(t.device[k]));
    ASSERT_TRUE(w.write_fingertip(t.fingertips[k]));
  }
  for (std::size_t i = 0; i < t.frames.size(); ++i) {
    if (t.meta.store == FrameStore::kPng) spit(dir / t.frames[i].image, "png bytes");
    ASSERT_TRUE(w.write_frame(t.frames[i], t.scene[i], t.fits[i]));
  }
  w.finish();
}

}  // namespace spidar::session::testing
