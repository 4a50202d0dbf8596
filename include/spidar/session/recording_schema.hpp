#pragma once
/// The one definition of a session recording (`spidar-mr run --record DIR`, read back by
/// `spidar-mr replay DIR`; docs/recording.md describes it for users). The writer
/// (recording_writer.hpp) and the reader (recording_reader.hpp) both take the file names, the
/// format version and every file's columns from here, and share the row types below.
///
/// A recording is a folder:
///   session.json     format, version, sizes, rates, counts; written at the start with
///                    "complete": false and again, atomically, at the very end with
///                    "complete": true, the row count of every CSV and the seconds it holds (the
///                    completion marker: a recording without it was interrupted);
///   config.yaml      the live config as used;
///   device.csv       one row per servo cycle at the device boundary (DeviceCycleRecord);
///   fingertips.csv   one row per servo cycle as the loop published it (FingertipSample, with the
///                    strings' tensions and motor commands: servo_output_columns);
///   frames.csv       one row per processed camera frame (FrameRow);
///   scene.csv        the scene's shape poses per frame (one row per frame and shape);
///   fits.csv         the live registration's fit per frame and hand (FitRow);
///   camera.mp4 / camera.avi, or frames/NNNNNN.png: the camera frames (session.json
///                    "frames_file" names the video; frames.csv "image" the PNG).
/// CSV files are comma-separated with one header row of column names (found by name on reading),
/// '\n' line ends (a '\r' before it is accepted), integers in decimal and floating-point numbers
/// with 17 significant digits (they read back bit for bit). Times are the host's monotonic clock
/// (CLOCK_MONOTONIC) in ns.
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "spidar/core/types.hpp"
#include "spidar/device/device.hpp"
#include "spidar/device/servo_types.hpp"
#include "spidar/hand/parameters.hpp"

namespace spidar::session {

/// session.json "format".
inline constexpr std::string_view kRecordingFormat = "spidar-mr recording";
/// session.json "version". 1: the first format (no completion marker; fits.csv without
/// "finite"). 2: completion marker ("complete", "rows", "seconds"), "frames_file", fits.csv
/// "finite" column. Later version-2 recordings add optional columns (servo_output_columns,
/// fit_size_columns): a reader takes a file with all of a group's columns or none.
inline constexpr int kRecordingVersion = 2;

/// Bounds on what a recording's numbers can be: the reader refuses a number beyond them as damage,
/// and the writer keeps within them (it saturates a sample's or a scene pose's coordinate, and
/// marks a fit beyond them not finite), so that a run's own recording always replays. Generous:
/// they keep out values whose use would overflow (1e308), not unusual ones.
namespace recording_bounds {
inline constexpr double kPosition_m = 100.0;  ///< |a world coordinate| [m]
inline constexpr double kForce_N = 1e4;       ///< |a force or a string tension| [N]
inline constexpr double kCost = 1e12;         ///< a fit's cost (dimensionless, >= 0)
inline constexpr double kPoseParameter = 1e3; ///< |a pose parameter| (wrist [m], rotation vector and joints [rad])
}  // namespace recording_bounds

/// File names inside a recording folder.
namespace recording_files {
inline constexpr std::string_view kSession = "session.json";
inline constexpr std::string_view kConfig = "config.yaml";
inline constexpr std::string_view kDevice = "device.csv";
inline constexpr std::string_view kFingertips = "fingertips.csv";
inline constexpr std::string_view kFrames = "frames.csv";
inline constexpr std::string_view kScene = "scene.csv";
inline constexpr std::string_view kFits = "fits.csv";
inline constexpr std::string_view kFramesDir = "frames";  ///< PNG frames: frames/NNNNNN.png
}  // namespace recording_files

/// How camera frames are stored: H.264 video (small, lossy), Motion-JPEG (larger, nearly
/// lossless) or PNG files (lossless: replay reproduces the live fits exactly).
enum class FrameStore { kVideo, kMjpg, kPng };

/// session.json: what a recording needs to know once.
struct RecordingMeta {
  int width = 0, height = 0;  ///< camera frame size [px]
  double fps = 30;            ///< camera rate [frames/s]
  int string_count = 0;       ///< strings of the device (device.csv has that many counts/commands)
  int finger_count = 0;       ///< fingers the servo loop tracks (fingertips' finger_count)
  std::string device_name;
  FrameStore store = FrameStore::kVideo;
  /// Video stores: the video file's name in the folder ("camera.mp4", "camera.avi"); PNG: "frames".
  std::string frames_file;
  std::string frames_codec;  ///< "mp4/h264", "avi/mjpg", ..., "png"
  std::array<Vec3, 2> initial_r_W_hand{Vec3::Zero(), Vec3::Zero()};  ///< rotation vectors [rad], world
};

/// session.json's completion marker: rows in each CSV and the time span of the recording.
struct RecordingCounts {
  std::uint64_t device = 0, fingertips = 0, frames = 0, scene = 0, fits = 0;
  double seconds = 0;  ///< newest minus oldest fingertip sample (frames if none) [s]
};

/// device.csv: one servo cycle at the device boundary.
struct DeviceCycleRecord {
  std::uint64_t seq = 0;  ///< 1, 2, 3, ... per write (gaps: rows lost before they were written)
  device::EncoderReading reading;  ///< host_time_ns [ns], device_time_us [µs], status, repeats, counts
  int command_count = 0;
  std::array<std::int32_t, device::kMaxDeviceStrings> commands{};  ///< motor commands [DAC counts]
};

/// frames.csv: one processed camera frame and the fingertip sample its registration used.
struct FrameRow {
  std::int64_t index = 0;          ///< processed-frame number (0, 1, 2, ...)
  std::int64_t t_exposure_ns = 0;  ///< host monotonic [ns]
  /// PNG store: the image's path relative to the folder; video: the frame number in the video.
  std::string image;
  device::FingertipSample measured;  ///< t_ns = t_exposure_ns; cycle not recorded (0)
};

/// fits.csv: the live registration's result for one frame and hand.
struct FitRow {
  std::int64_t frame = 0;
  int hand = 0;  ///< 0 left, 1 right
  int iterations = 0;
  bool converged = false;
  /// false: the live fit had a NaN or infinite value; its numbers are then written empty.
  bool finite = true;
  double cost_initial = 0, cost_final = 0;
  /// Final cost per term: fingertip, wrist, joint_ball, silhouette, prior.
  std::array<double, 5> terms{};
  /// The paper's 17 hand parameters (include/spidar/hand/parameters.hpp); a little finger of its
  /// own (registration's little_free) is not recorded: a replay fits it again.
  std::array<double, hand::kPaperParamCount> q{};
  /// The hand model's length and width the fit used [m] (they change while the shape is
  /// personalised: registration/shape_estimator.hpp); 0: not recorded (a recording made before
  /// fit_size_columns were written, or a writer that did not know them).
  double length_m = 0, width_m = 0;
};

/// Column names of each CSV, in the order the writer writes them. The reader finds columns by
/// these names and requires exactly this set.
std::vector<std::string> device_columns(int string_count);
std::vector<std::string> fingertip_columns();  ///< t_ns, cycle, then sample_columns()
/// fingertips.csv's servo output columns after fingertip_columns(): tension0..tensionN-1 (the
/// tension the cycle solved per string [N]) and motor0..motorN-1 (the motor command sent [DAC
/// counts]) for the N = session.json string_count strings. Optional on reading: a version-2
/// recording made before they were written has none of them (its samples read with
/// string_count 0); one that has any must have all.
std::vector<std::string> servo_output_columns(int string_count);
std::vector<std::string> frame_columns();      ///< frame, t_exposure_ns, image, then sample_columns()
std::vector<std::string> scene_columns();      ///< frame, shape, px..pz [m], qw..qz (unit), world
std::vector<std::string> fit_columns();
/// fits.csv's columns after fit_columns(): length_m, width_m (FitRow). Optional on reading: a
/// recording made before they were written has none (its rows read with sizes 0).
std::vector<std::string> fit_size_columns();
/// A fingertip sample's columns: faults, consistent, finger_count, p0x..p7z [m] (world),
/// f0x..f7z [N] (world).
std::vector<std::string> sample_columns();

/// The comma-joined header row (no line end).
std::string header_row(const std::vector<std::string>& columns);

/// "video", "mjpg", "png" (session.json "frames"); and back (false if unknown).
std::string_view frame_store_name(FrameStore store);
bool parse_frame_store(std::string_view name, FrameStore* store);

/// Largest |‖q‖ − 1| accepted for a scene quaternion.
inline constexpr double kUnitQuaternionTolerance = 1e-6;

}  // namespace spidar::session
