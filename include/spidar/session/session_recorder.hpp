#pragma once
/// Recording a live session (`spidar-mr run --record DIR`; the format is docs/recording.md):
///
///   RecordingDevice  wraps the device: every servo cycle's encoder reading and the motor commands
///                    written after it go into a lock-free ring (no allocation, no lock in the
///                    servo thread);
///   SessionRecorder  a FrameSink: a writer thread drains that ring and the servo loop's
///                    fingertip samples (positions, forces, the strings' tensions and motor
///                    commands) into the recording's CSVs, and writes each processed camera frame
///                    (video or PNG), the scene poses, the fingertip sample the frame was
///                    registered with and the fit. The files and their columns are
///                    RecordingWriter's (recording_schema.hpp); this is the threads and the frame
///                    images around it.
#include <array>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <opencv2/core/mat.hpp>
#include <string>
#include <thread>
#include <vector>

#include "spidar/core/scene_snapshot.hpp"
#include "spidar/core/seqlock.hpp"
#include "spidar/device/device.hpp"
#include "spidar/device/servo_loop.hpp"
#include "spidar/hand/hand_shape.hpp"
#include "spidar/hand/parameters.hpp"
#include "spidar/registration/successive_adjustment.hpp"
#include "spidar/render/video_output.hpp"
#include "spidar/session/frame_sink.hpp"
#include "spidar/session/recording_writer.hpp"

namespace spidar::session {

/// A Device that forwards everything to another and records reads and writes.
class RecordingDevice final : public device::Device {
 public:
  explicit RecordingDevice(device::Device& inner) : inner_(inner), ring_(std::make_unique<Ring>()) {}
  Status open() override { return inner_.open(); }
  void close() override { inner_.close(); }
  const device::DeviceInfo& info() const override { return inner_.info(); }
  Status read(device::EncoderReading& out) override;
  Status write(std::span<const std::int32_t> commands) override;
  void request_safe_state() override { inner_.request_safe_state(); }
  void clear_safe_state() override { inner_.clear_safe_state(); }
  device::DeviceStatus status() const override { return inner_.status(); }
  Status check_rate(double rate_hz) const override { return inner_.check_rate(rate_hz); }

  static constexpr std::size_t kRing = 4096;
  using Ring = core::SampleRing<DeviceCycleRecord, kRing>;
  const Ring& ring() const { return *ring_; }

 private:
  device::Device& inner_;
  std::unique_ptr<Ring> ring_;
  DeviceCycleRecord pending_;
  std::uint64_t seq_ = 0;
};

/// What a recording needs to know once, at the start (session.json, config.yaml).
struct RecorderSetup {
  std::string config_yaml;           ///< the resolved live config (config.yaml)
  int width = 0, height = 0;
  double fps = 30;
  int string_count = 0;
  int finger_count = 0;
  std::array<Vec3, 2> initial_r_W_hand{Vec3::Zero(), Vec3::Zero()};
  std::string device_name;
};

/// One processed camera frame.
struct FrameRecord {
  std::int64_t index = 0;           ///< processed-frame number (0, 1, 2, ...)
  std::int64_t t_exposure_ns = 0;   ///< host monotonic [ns]
  cv::Mat bgr;                      ///< owned copy
  device::FingertipSample measured; ///< the sample registration used (interpolated at exposure)
  std::vector<Pose> scene_poses;    ///< SceneSnapshot shape poses, in snapshot order
  std::array<hand::HandParams, 2> hands;
  std::array<registration::FitReport, 2> fits;
  std::array<hand::HandDimensions, 2> sizes;  ///< the hand models the fits used (length, width [m])
};

class SessionRecorder final : public FrameSink {
 public:
  /// Creates DIR (it must not hold a recording already) and writes config.yaml and session.json
  /// (without its completion marker). The writer thread, started by on_start, polls `device`
  /// and `servo` (both must outlive stop()). Throws SpidarError naming the path on failure.
  SessionRecorder(const std::string& dir, FrameStore store, const RecorderSetup& setup,
                  const RecordingDevice& device, const device::ServoLoop& servo);
  ~SessionRecorder() override;
  /// Starts the writer thread.
  void on_start() override;
  /// Queues the frame (a copy of its image, its sample, scene poses and fits) for writing;
  /// blocks while 16 frames wait.
  void on_frame(const FrameEvent& e) override;
  /// stop().
  void on_end(const SessionSummary& s) override;
  /// Frame thread: queues a frame for writing (blocks while 16 frames wait).
  void add_frame(FrameRecord frame);
  /// Drains everything, closes the files and, if every write succeeded, writes the completion
  /// marker (session.json "complete": true). Call after the servo loop has stopped. A failure
  /// is kept in error(), never thrown.
  void stop();
  const std::string& dir() const { return dir_; }
  std::uint64_t device_records() const { return device_written_; }
  std::uint64_t fingertip_records() const { return samples_written_; }
  std::uint64_t frames() const { return frames_written_; }
  std::uint64_t lost() const { return lost_; }  ///< ring entries overwritten before written
  /// The first write failure, naming the file ("DIR/device.csv: write failed: No space left on
  /// device"); empty if none. Set by the writer thread: read it after stop().
  const std::string& error() const { return error_; }

 private:
  void run();
  void drain();
  void write_frame(FrameRecord& f);
  /// Keeps the first error.
  void note_error(const std::string& e);

  std::string dir_;
  FrameStore store_;
  RecorderSetup meta_;
  const RecordingDevice* device_ = nullptr;
  const device::ServoLoop* servo_ = nullptr;
  std::unique_ptr<RecordingWriter> writer_;
  std::unique_ptr<render::VideoOutput> video_;
  std::vector<DeviceCycleRecord> dev_buf_;
  std::vector<device::FingertipSample> sample_buf_;
  std::uint64_t last_dev_seq_ = 0, last_cycle_ = 0;
  bool have_cycle_ = false;
  std::uint64_t device_written_ = 0, samples_written_ = 0, frames_written_ = 0, lost_ = 0;
  std::string error_;

  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<FrameRecord> queue_;
  bool stop_ = false;
  bool stopped_ = false;
  std::thread thread_;
};

}  // namespace spidar::session
