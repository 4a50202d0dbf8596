#pragma once
/// Reading a session recording (recording_schema.hpp) back, checking everything: a damaged
/// recording, or one from another version, is refused with a message naming the file, the line
/// and the column (or the session.json key) and what was expected. Checked:
///   - session.json: format, version, every key's type and range, and the completion marker (a
///     recording without it is refused as "incomplete, N s");
///   - every CSV: the header row has exactly the schema's column names (found by name, any
///     order), every row has every field, integers are integers in range, floating-point numbers
///     are finite (no nan, no inf), the last row ends with a line end (else it was cut off);
///     a '\r' before the '\n' (CRLF files) is accepted;
///   - order: device seq, fingertip cycle and frame numbers strictly increase, their times never
///     decrease; scene rows list each frame's shapes 0, 1, ... and fits rows hands 0 and 1 of
///     each frame, in frames.csv's order; scene quaternions are unit;
///   - agreement: row counts equal session.json's "rows", samples' finger_count its
///     finger_count, device.csv has its string_count of counts and commands;
///   - frames: PNG paths are relative and stay inside the folder (no "..", no absolute path, no
///     symbolic link out) and exist; video frame numbers are 0, 1, 2, ... and the video exists.
#include <array>
#include <cstdint>
#include <functional>
#include <istream>
#include <string>
#include <string_view>
#include <vector>

#include "spidar/core/pose.hpp"
#include "spidar/core/result.hpp"
#include "spidar/session/recording_schema.hpp"

namespace spidar::session {

/// A recording that is damaged, incomplete or from another version. `what()` is
/// `FILE:LINE:COLUMN: what was wrong and what was expected` (LINE and COLUMN 1-based; both are
/// left out when 0, e.g. for a session.json key, which the message names instead).
class RecordingError : public SpidarError {
 public:
  RecordingError(std::string file, int line, int column, const std::string& message);
  const std::string& file() const { return file_; }
  int line() const { return line_; }
  int column() const { return column_; }

 private:
  std::string file_;
  int line_;
  int column_;
};

/// session.json as read.
struct SessionJson {
  RecordingMeta meta;
  bool complete = false;
  RecordingCounts rows;  ///< only when complete
};

/// Parses session.json's text (`name` stands for the file in messages). Throws RecordingError
/// for invalid JSON, another format or version, a missing key or a value out of range. The
/// completion marker is read but not required here (read_recording requires it).
SessionJson parse_session_json(std::string_view text, const std::string& name);

/// Each of these reads one CSV from `in` (`name` stands for the file in messages) and checks it
/// on its own: header, fields, numbers, order (see above). `finger_count` < 0 accepts any
/// finger_count from 0 to 8 in samples. Throw RecordingError.
std::uint64_t read_device_csv(std::istream& in, const std::string& name, int string_count,
                              const std::function<void(const DeviceCycleRecord&)>& on_row = {});
/// fingertips.csv: with `string_count` > 0 its servo output columns (tensions, motor commands)
/// are read if the file has them (samples then have that string_count), else left 0.
std::vector<device::FingertipSample> read_fingertips_csv(std::istream& in, const std::string& name,
                                                         int finger_count, int string_count = 0);
/// `check_image(row, image)` (row 0, 1, ...) returns what is wrong with a frame's image field, or
/// "" if nothing (read_recording checks PNG paths and video frame numbers with it).
std::vector<FrameRow> read_frames_csv(
    std::istream& in, const std::string& name, int finger_count,
    const std::function<std::string(std::size_t, const std::string&)>& check_image = {});
/// scene.csv: poses per frame, in file order; `frames` gets each group's frame number.
std::vector<std::vector<Pose>> read_scene_csv(std::istream& in, const std::string& name,
                                              std::vector<std::int64_t>* frames);
std::vector<FitRow> read_fits_csv(std::istream& in, const std::string& name);

/// A whole recording, read and checked.
struct Recording {
  std::string dir;
  RecordingMeta meta;
  RecordingCounts rows;
  std::string config_path;  ///< DIR/config.yaml (checked to exist; its content is the app's)
  std::uint64_t device_rows = 0;
  std::vector<device::FingertipSample> fingertips;  ///< oldest first
  std::vector<FrameRow> frames;                     ///< in processing order
  std::vector<std::vector<Pose>> scene;             ///< per frame (same order); empty if no shapes
  std::vector<std::array<FitRow, 2>> fits;          ///< per frame: left, right
  std::string video_path;                           ///< video stores: DIR/frames_file
};

/// Reads and checks the recording in folder `dir`. Throws RecordingError, or core::FileError for
/// a file that is missing or cannot be read.
Recording read_recording(const std::string& dir);

/// The seconds a recording's fingertips.csv spans (frames.csv if it has no rows), reading
/// leniently up to the first damaged row: what an incomplete recording holds.
double recorded_seconds(const std::string& dir);

}  // namespace spidar::session
