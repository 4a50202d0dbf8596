#pragma once
/// Writing a session recording (recording_schema.hpp) from a running session.
///
/// The CSVs grow while the session runs, so they cannot be written atomically; instead every write
/// is checked and the first failure (a full disk, an I/O error) is kept and reported naming the
/// file. session.json and config.yaml are written whole (core::write_file_atomic). session.json is
/// written first with "complete": false and last, by finish(), with "complete": true, the row
/// counts and the seconds held: a recording without that marker was interrupted, and replay
/// refuses it ("incomplete, N s").
///
/// Not thread-safe: one thread (the recorder's writer thread) calls everything after construction.
#include <array>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "spidar/core/pose.hpp"
#include "spidar/session/recording_schema.hpp"

namespace spidar::session {

class CheckedFile;

/// SpidarError unless `dir` is a folder a recording may go into: one that does not exist yet, or
/// an empty one. A recording's files (config.yaml, device.csv, frames/...) would overwrite what
/// another folder holds; one holding session.json is named as a recording already.
void check_new_recording_folder(const std::string& dir);

class RecordingWriter {
 public:
  /// Creates the folder `dir` (it must not hold a session.json already; callers check the whole
  /// folder first with check_new_recording_folder), and frames/ for the PNG
  /// store; writes config.yaml (`config_yaml`) and session.json ("complete": false); creates the
  /// CSVs with their header rows. Throws core::FileError naming the path on any failure, or
  /// SpidarError if `dir` holds a recording already or `meta` is out of range.
  RecordingWriter(std::string dir, const RecordingMeta& meta, std::string_view config_yaml);
  ~RecordingWriter();
  RecordingWriter(const RecordingWriter&) = delete;
  RecordingWriter& operator=(const RecordingWriter&) = delete;

  /// Names the video file and its codec once it is open (rewrites session.json). Throws FileError.
  void set_frames_file(const std::string& file, const std::string& codec);

  /// Append one row each. They return false once any write has failed (see error()).
  bool write_device(const DeviceCycleRecord& r);
  bool write_fingertip(const device::FingertipSample& s);
  /// frames.csv's row, the frame's scene poses (scene.csv) and both hands' fits (fits.csv).
  bool write_frame(const FrameRow& frame, std::span<const Pose> scene, const std::array<FitRow, 2>& fits);

  /// Closes the CSVs (flush, fsync, close, each checked), then writes session.json with the
  /// completion marker. Throws core::FileError naming the file on the first failure (the
  /// recording then has no marker). Idempotent once it succeeded.
  void finish();
  /// Closes the CSVs (what they hold is flushed) without the completion marker: for a recording
  /// that failed elsewhere (a frame image that could not be written). Never throws.
  void close_incomplete();

  /// The first write failure ("PATH: write failed: No space left on device"), empty if none.
  std::string error() const;
  const RecordingCounts& counts() const { return counts_; }
  const std::string& dir() const { return dir_; }
  const RecordingMeta& meta() const { return meta_; }

 private:
  void write_session_json(bool complete) const;

  std::string dir_;
  RecordingMeta meta_;
  std::unique_ptr<CheckedFile> device_, fingertips_, frames_, scene_, fits_;
  RecordingCounts counts_;
  std::int64_t t_first_ns_ = 0, t_last_ns_ = 0, frame_first_ns_ = 0, frame_last_ns_ = 0;
  bool finished_ = false;
};

/// One CSV row (with its '\n') exactly as the writer writes it. Also used by the fuzz target to
/// check that what the reader accepts writes back to rows that read the same.
std::string device_row_text(const DeviceCycleRecord& r, int string_count);
/// fingertips.csv: with the servo output columns of `string_count` strings (0: none; strings past
/// the sample's string_count are written 0).
std::string fingertip_row_text(const device::FingertipSample& s, int string_count = 0);
std::string frame_row_text(const FrameRow& f);
std::string scene_row_text(std::int64_t frame, std::size_t shape, const Pose& X_WS);
std::string fit_row_text(const FitRow& r);

/// Shortest text that reads back to the same double (17 significant digits).
std::string number_text(double v);

}  // namespace spidar::session
