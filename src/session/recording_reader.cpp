#include "spidar/session/recording_reader.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <nlohmann/json.hpp>

#include "csv_cursor.hpp"
#include "spidar/core/config.hpp"
#include "spidar/core/file_read.hpp"

namespace spidar::session {
namespace {

namespace fs = std::filesystem;
namespace files = recording_files;
using nlohmann::json;

std::string location(const std::string& file, int line, int column) {
  std::string s = core::printable_for_message(file);
  if (line > 0) s += ":" + std::to_string(line);
  if (line > 0 && column > 0) s += ":" + std::to_string(column);
  return s;
}

std::string short_number(double v) { return core::number_for_message(v, 9); }

// Bounds on what a recording's numbers can be (recording_schema.hpp; the writer keeps within them).
constexpr double kMaxPosition_m = recording_bounds::kPosition_m;
constexpr double kMaxForce_N = recording_bounds::kForce_N;
constexpr double kMaxCost = recording_bounds::kCost;
constexpr double kMaxPoseParameter = recording_bounds::kPoseParameter;

/// The sample columns of the current row (faults ... f7z).
device::FingertipSample read_sample(const CsvCursor& c, int finger_count) {
  device::FingertipSample s;
  s.faults = static_cast<std::uint32_t>(c.unsigned_integer(c.col("faults"), UINT32_MAX));
  s.consistent = static_cast<std::uint32_t>(c.unsigned_integer(c.col("consistent"), UINT32_MAX));
  const std::size_t fc = c.col("finger_count");
  s.finger_count = static_cast<int>(c.integer(fc, 0, device::kMaxFingers));
  if (finger_count >= 0 && s.finger_count != finger_count)
    c.fail(fc, "expected " + std::to_string(finger_count) + " (session.json finger_count), got " +
                   std::to_string(s.finger_count));
  const std::size_t p0 = c.col("p0x"), f0 = c.col("f0x");
  for (int f = 0; f < device::kMaxFingers; ++f)
    for (int k = 0; k < 3; ++k) {
      s.p_W[f][k] = c.number(p0 + static_cast<std::size_t>(3 * f + k), -kMaxPosition_m, kMaxPosition_m,
                             "a fingertip coordinate [m]");
      s.f_W[f][k] = c.number(f0 + static_cast<std::size_t>(3 * f + k), -kMaxForce_N, kMaxForce_N,
                             "a force component [N]");
    }
  return s;
}

// --- session.json ------------------------------------------------------------------------------

class JsonKeys {
 public:
  /// `prefix`: the object's own path for nested keys ("rows."), so that a message names
  /// "rows.frames", not a "frames" that could be the top level's.
  JsonKeys(const json& j, const std::string& name, std::string prefix = "")
      : j_(j), name_(name), prefix_(std::move(prefix)) {}
  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw RecordingError(name_, 0, 0, "key \"" + prefix_ + key + "\": " + what);
  }
  const json& at(const std::string& key) const {
    const auto it = j_.find(key);
    if (it == j_.end()) fail(key, "missing (docs/recording.md lists the keys)");
    return *it;
  }
  std::int64_t integer(const std::string& key, std::int64_t lo, std::int64_t hi, const json* j = nullptr) const {
    const json& v = j ? *j : at(key);
    if (!v.is_number_integer() || v.get<std::int64_t>() < lo || v.get<std::int64_t>() > hi ||
        (v.is_number_unsigned() && v.get<std::uint64_t>() > static_cast<std::uint64_t>(hi)))
      fail(key, "expected an integer from " + std::to_string(lo) + " to " + std::to_string(hi) + ", got " + v.dump());
    return v.get<std::int64_t>();
  }
  double number(const std::string& key, double lo, double hi, const json* j = nullptr) const {
    const json& v = j ? *j : at(key);
    if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() < lo || v.get<double>() > hi)
      fail(key, "expected a number from " + json(lo).dump() + " to " + json(hi).dump() + ", got " + v.dump());
    return v.get<double>();
  }
  std::string string(const std::string& key) const {
    const json& v = at(key);
    if (!v.is_string()) fail(key, "expected a string, got " + v.dump());
    return v.get<std::string>();
  }

 private:
  const json& j_;
  const std::string& name_;
  std::string prefix_;
};

/// A file name inside the folder: no separator, not "." or "..", not empty.
bool plain_file_name(const std::string& s) {
  return !s.empty() && s != "." && s != ".." && s.find('/') == std::string::npos && s.find('\0') == std::string::npos;
}

std::ifstream open_csv(const fs::path& p) {
  const std::string path = p.string();
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    throw core::FileError(path, "missing (a recording has session.json, config.yaml, device.csv, fingertips.csv, "
                                "frames.csv, scene.csv and fits.csv)");
  if (!S_ISREG(st.st_mode)) throw core::FileError(path, "is not a regular file");
  std::ifstream in(p, std::ios::binary);
  if (!in) throw core::FileError(path, "cannot open file (is it readable?)");
  return in;
}

void require_rows(const std::string& file, int line, std::uint64_t got, std::uint64_t expected, const char* key) {
  if (got != expected)
    throw RecordingError(file, line, 1,
                         std::to_string(got) + " rows, but session.json says " + std::to_string(expected) + " (rows." +
                             key + "): the file is damaged or belongs to another recording");
}

/// True if `image` (relative to `dir`) stays inside `dir`, symbolic links resolved.
bool inside(const fs::path& dir, const std::string& image) {
  const fs::path rel(image);
  if (image.empty() || rel.is_absolute() || image.find('\0') != std::string::npos) return false;
  for (const auto& part : rel)
    if (part == "..") return false;
  std::error_code ec;
  const fs::path base = fs::weakly_canonical(dir, ec);
  if (ec) return false;
  const fs::path full = fs::weakly_canonical(dir / rel, ec);
  if (ec) return false;
  const auto [b, f] = std::mismatch(base.begin(), base.end(), full.begin(), full.end());
  return b == base.end() && f != full.end();
}

/// The 1-based line and column of byte `at` (0-based) of `text` (clamped to its end).
std::pair<int, int> line_and_column(std::string_view text, std::size_t at) {
  at = std::min(at, text.size());
  int line = 1, column = 1;
  for (std::size_t i = 0; i < at; ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return {line, column};
}

}  // namespace

RecordingError::RecordingError(std::string file, int line, int column, const std::string& message)
    : SpidarError(location(file, line, column) + ": " + message),
      file_(std::move(file)),
      line_(line),
      column_(column) {}

SessionJson parse_session_json(std::string_view text, const std::string& name) {
  json j;
  try {
    j = json::parse(text);
  } catch (const json::parse_error& e) {
    // e.byte is the 1-based offset of the error.
    const auto [line, column] = line_and_column(text, e.byte == 0 ? 0 : e.byte - 1);
    throw RecordingError(name, line, column, "not valid JSON (expected a recording's session.json)");
  } catch (const json::out_of_range& e) {
    // A number beyond a double's range ("number overflow parsing '1e999'"): the parser gives no
    // offset, so the number is found in the text.
    const std::string what = e.what();
    const std::size_t q0 = what.find('\''), q1 = q0 == std::string::npos ? q0 : what.find('\'', q0 + 1);
    const std::string token = q1 == std::string::npos ? std::string() : what.substr(q0 + 1, q1 - q0 - 1);
    const std::size_t at = token.empty() ? std::string_view::npos : text.find(token);
    const auto [line, column] = at == std::string_view::npos ? std::pair{0, 0} : line_and_column(text, at);
    throw RecordingError(name, line, column,
                         "a number out of range" + (token.empty() ? std::string() : " ('" + token + "')") +
                             " (expected a recording's session.json with finite numbers)");
  } catch (const json::exception& e) {
    throw RecordingError(name, 0, 0, std::string("not a readable session.json: ") + e.what());
  }
  if (!j.is_object()) throw RecordingError(name, 0, 0, "expected a JSON object (a recording's session.json)");
  const JsonKeys k(j, name);
  if (!j.contains("format") || !j["format"].is_string() || j["format"].get<std::string>() != kRecordingFormat)
    k.fail("format", "expected \"" + std::string(kRecordingFormat) + "\", got " +
                         (j.contains("format") ? j["format"].dump() : std::string("nothing")) +
                         " (is this a folder written by run --record?)");
  if (!j.contains("version") || !j["version"].is_number_integer() || j["version"].get<std::int64_t>() != kRecordingVersion)
    k.fail("version", "this recording has format version " + (j.contains("version") ? j["version"].dump() : "(none)") +
                          "; this spidar-mr reads version " + std::to_string(kRecordingVersion) +
                          " (record it again, or replay it with the spidar-mr that recorded it)");
  SessionJson s;
  RecordingMeta& m = s.meta;
  m.width = static_cast<int>(k.integer("width", 1, 16384));
  m.height = static_cast<int>(k.integer("height", 1, 16384));
  m.fps = k.number("fps", 1e-3, 1000);
  m.string_count = static_cast<int>(k.integer("string_count", 1, device::kMaxDeviceStrings));
  m.finger_count = static_cast<int>(k.integer("finger_count", 1, device::kMaxFingers));
  m.device_name = k.string("device");
  const std::string store = k.string("frames");
  if (!parse_frame_store(store, &m.store)) k.fail("frames", "expected \"video\", \"mjpg\" or \"png\", got \"" + store + "\"");
  m.frames_file = k.string("frames_file");
  if (!plain_file_name(m.frames_file))
    k.fail("frames_file", "expected a file name inside the recording folder, got \"" + m.frames_file + "\"");
  m.frames_codec = k.string("frames_codec");
  const json& r0 = k.at("initial_r_W_hand");
  if (!r0.is_array() || r0.size() != 2) k.fail("initial_r_W_hand", "expected 2 rotation vectors [rad]");
  for (std::size_t h = 0; h < 2; ++h) {
    if (!r0[h].is_array() || r0[h].size() != 3) k.fail("initial_r_W_hand", "expected 3 numbers per hand");
    for (std::size_t i = 0; i < 3; ++i)
      m.initial_r_W_hand[h][static_cast<int>(i)] = k.number("initial_r_W_hand", -100, 100, &r0[h][i]);
  }
  const json& complete = k.at("complete");
  if (!complete.is_boolean()) k.fail("complete", "expected true or false, got " + complete.dump());
  s.complete = complete.get<bool>();
  if (s.complete) {
    const json& rows = k.at("rows");
    if (!rows.is_object()) k.fail("rows", "expected an object of row counts");
    const JsonKeys r(rows, name, "rows.");
    constexpr std::int64_t kMaxRows = std::int64_t{1} << 50;
    s.rows.device = static_cast<std::uint64_t>(r.integer("device", 0, kMaxRows));
    s.rows.fingertips = static_cast<std::uint64_t>(r.integer("fingertips", 0, kMaxRows));
    s.rows.frames = static_cast<std::uint64_t>(r.integer("frames", 0, kMaxRows));
    s.rows.scene = static_cast<std::uint64_t>(r.integer("scene", 0, kMaxRows));
    s.rows.fits = static_cast<std::uint64_t>(r.integer("fits", 0, kMaxRows));
    s.rows.seconds = k.number("seconds", 0, 1e9);
  }
  return s;
}

std::uint64_t read_device_csv(std::istream& in, const std::string& name, int string_count,
                              const std::function<void(const DeviceCycleRecord&)>& on_row) {
  if (string_count < 1 || string_count > device::kMaxDeviceStrings)
    throw RecordingError(name, 0, 0, "string_count " + std::to_string(string_count) + " out of range");
  CsvCursor c(in, name, device_columns(string_count));
  const std::size_t seq = c.col("seq"), host = c.col("host_time_ns"), dev_t = c.col("device_time_us"),
                    status = c.col("status"), repeats = c.col("repeats"), count0 = c.col("count0"),
                    command0 = c.col("command0");
  std::uint64_t rows = 0;
  DeviceCycleRecord r, prev;
  r.reading.string_count = string_count;
  r.command_count = string_count;
  while (c.next()) {
    r.seq = c.unsigned_integer(seq);
    if (r.seq == 0 || (rows > 0 && r.seq <= prev.seq))
      c.fail(seq, "expected a number above " + std::to_string(rows > 0 ? prev.seq : 0) +
                      " (seq increases from row to row), got " + std::to_string(r.seq));
    r.reading.host_time_ns = c.integer(host, 0);
    if (rows > 0 && r.reading.host_time_ns < prev.reading.host_time_ns)
      c.fail(host, "time goes back (" + std::to_string(r.reading.host_time_ns) + " after " +
                       std::to_string(prev.reading.host_time_ns) + " on the previous row)");
    r.reading.device_time_us = static_cast<std::uint32_t>(c.unsigned_integer(dev_t, UINT32_MAX));
    r.reading.status_flags = static_cast<std::uint32_t>(c.unsigned_integer(status, UINT32_MAX));
    r.reading.repeats = static_cast<std::uint32_t>(c.unsigned_integer(repeats, UINT32_MAX));
    for (int i = 0; i < string_count; ++i) {
      r.reading.counts[i] = static_cast<std::int32_t>(c.integer(count0 + static_cast<std::size_t>(i), INT32_MIN, INT32_MAX));
      r.commands[i] = static_cast<std::int32_t>(c.integer(command0 + static_cast<std::size_t>(i), INT32_MIN, INT32_MAX));
    }
    if (on_row) on_row(r);
    prev = r;
    ++rows;
  }
  return rows;
}

std::vector<device::FingertipSample> read_fingertips_csv(std::istream& in, const std::string& name, int finger_count,
                                                         int string_count) {
  CsvCursor c(in, name, fingertip_columns(), servo_output_columns(std::clamp(string_count, 0, device::kMaxDeviceStrings)));
  const std::size_t t = c.col("t_ns"), cycle = c.col("cycle");
  const bool outputs = c.has_optional() && string_count > 0;
  const std::size_t tension0 = outputs ? c.col("tension0") : 0, motor0 = outputs ? c.col("motor0") : 0;
  std::vector<device::FingertipSample> out;
  while (c.next()) {
    device::FingertipSample s = read_sample(c, finger_count);
    if (outputs) {
      s.string_count = string_count;
      for (int i = 0; i < string_count; ++i) {
        const auto k = static_cast<std::size_t>(i);
        s.tension[k] = c.number(tension0 + k, -kMaxForce_N, kMaxForce_N, "a string tension [N]");
        s.command[k] = static_cast<std::int32_t>(c.integer(motor0 + k, INT32_MIN, INT32_MAX));
      }
    }
    s.t_ns = c.integer(t, 0);
    s.cycle = c.unsigned_integer(cycle);
    if (!out.empty() && s.cycle <= out.back().cycle)
      c.fail(cycle, "expected a cycle above " + std::to_string(out.back().cycle) + " (cycles increase), got " +
                        std::to_string(s.cycle));
    if (!out.empty() && s.t_ns < out.back().t_ns)
      c.fail(t, "time goes back (" + std::to_string(s.t_ns) + " after " + std::to_string(out.back().t_ns) +
                    " on the previous row)");
    out.push_back(s);
  }
  return out;
}

std::vector<FrameRow> read_frames_csv(std::istream& in, const std::string& name, int finger_count,
                                      const std::function<std::string(std::size_t, const std::string&)>& check_image) {
  CsvCursor c(in, name, frame_columns());
  const std::size_t frame = c.col("frame"), t = c.col("t_exposure_ns"), image = c.col("image");
  std::vector<FrameRow> out;
  while (c.next()) {
    FrameRow f;
    f.index = c.integer(frame, 0);
    if (f.index != static_cast<std::int64_t>(out.size()))
      c.fail(frame, "expected frame " + std::to_string(out.size()) + " (frames are numbered 0, 1, 2, ... in order), got " +
                        std::to_string(f.index));
    f.t_exposure_ns = c.integer(t, 0);
    if (!out.empty() && f.t_exposure_ns < out.back().t_exposure_ns)
      c.fail(t, "time goes back (" + std::to_string(f.t_exposure_ns) + " after " +
                    std::to_string(out.back().t_exposure_ns) + " on the previous row)");
    f.image = std::string(c.text(image));
    if (f.image.empty()) c.fail(image, "empty (expected a PNG path or a video frame number)");
    if (check_image) {
      if (const std::string e = check_image(out.size(), f.image); !e.empty())
        c.fail(image, e + ", got '" + core::printable_for_message(f.image) + "'");
    }
    f.measured = read_sample(c, finger_count);
    f.measured.t_ns = f.t_exposure_ns;
    out.push_back(std::move(f));
  }
  return out;
}

std::vector<std::vector<Pose>> read_scene_csv(std::istream& in, const std::string& name,
                                              std::vector<std::int64_t>* frames) {
  CsvCursor c(in, name, scene_columns());
  const std::size_t frame = c.col("frame"), shape = c.col("shape"), px = c.col("px"), qw = c.col("qw");
  std::vector<std::vector<Pose>> out;
  frames->clear();
  while (c.next()) {
    const std::int64_t f = c.integer(frame, 0);
    if (frames->empty() || f != frames->back()) {
      if (!frames->empty() && f < frames->back())
        c.fail(frame, "expected frame " + std::to_string(frames->back()) + " or later (rows in frame order), got " +
                          std::to_string(f));
      frames->push_back(f);
      out.emplace_back();
    }
    auto& poses = out.back();
    const std::int64_t s = c.integer(shape, 0);
    if (s != static_cast<std::int64_t>(poses.size()))
      c.fail(shape, "expected shape " + std::to_string(poses.size()) + " (each frame lists its shapes 0, 1, 2, ...), got " +
                        std::to_string(s));
    Pose X;
    X.p = Vec3(c.number(px, -kMaxPosition_m, kMaxPosition_m, "a position coordinate [m]"),
               c.number(px + 1, -kMaxPosition_m, kMaxPosition_m, "a position coordinate [m]"),
               c.number(px + 2, -kMaxPosition_m, kMaxPosition_m, "a position coordinate [m]"));
    const double w = c.number(qw), x = c.number(qw + 1), y = c.number(qw + 2), z = c.number(qw + 3);
    const double norm = std::sqrt(w * w + x * x + y * y + z * z);
    if (!(std::abs(norm - 1.0) <= kUnitQuaternionTolerance))
      c.fail(qw, "the orientation quaternion has norm " + short_number(norm) + ", expected a unit quaternion");
    X.R = Quat(w, x, y, z);
    poses.push_back(X);
  }
  return out;
}

std::vector<FitRow> read_fits_csv(std::istream& in, const std::string& name) {
  CsvCursor c(in, name, fit_columns(), fit_size_columns());
  const std::size_t frame = c.col("frame"), hand = c.col("hand"), iterations = c.col("iterations"),
                    converged = c.col("converged"), finite = c.col("finite"), cost0 = c.col("cost_initial"),
                    cost1 = c.col("cost_final"), term0 = c.col("fingertip"), q0 = c.col("q0");
  std::vector<FitRow> out;
  while (c.next()) {
    FitRow r;
    r.frame = c.integer(frame, 0);
    r.hand = static_cast<int>(c.integer(hand, 0, 1));
    const int want_hand = out.empty() || out.back().hand == 1 ? 0 : 1;
    if (r.hand != want_hand)
      c.fail(hand, "expected hand " + std::to_string(want_hand) + " (each frame has a row for hand 0, then hand 1)");
    if (want_hand == 1 && r.frame != out.back().frame)
      c.fail(frame, "expected frame " + std::to_string(out.back().frame) + " (hand 1 of the frame above), got " +
                        std::to_string(r.frame));
    if (want_hand == 0 && !out.empty() && r.frame <= out.back().frame)
      c.fail(frame, "expected a frame after " + std::to_string(out.back().frame) + " (rows in frame order), got " +
                        std::to_string(r.frame));
    r.iterations = static_cast<int>(c.integer(iterations, 0, 1'000'000));
    r.converged = c.integer(converged, 0, 1) == 1;
    r.finite = c.integer(finite, 0, 1) == 1;
    std::vector<std::size_t> numbers = {cost0, cost1};
    for (std::size_t i = 0; i < r.terms.size(); ++i) numbers.push_back(term0 + i);
    for (std::size_t i = 0; i < r.q.size(); ++i) numbers.push_back(q0 + i);
    if (r.finite) {
      r.cost_initial = c.number(cost0, 0.0, kMaxCost, "a cost");
      r.cost_final = c.number(cost1, 0.0, kMaxCost, "a cost");
      for (std::size_t i = 0; i < r.terms.size(); ++i) r.terms[i] = c.number(term0 + i, 0.0, kMaxCost, "a cost");
      for (std::size_t i = 0; i < r.q.size(); ++i)
        r.q[i] = c.number(q0 + i, -kMaxPoseParameter, kMaxPoseParameter, "a pose parameter [m or rad]");
    } else {
      for (std::size_t k : numbers)
        if (!c.empty(k)) c.fail(k, "expected an empty field (finite is 0: the live fit was not finite)");
      r.cost_initial = r.cost_final = std::nan("");
      r.terms.fill(std::nan(""));
      r.q.fill(std::nan(""));
    }
    if (c.has_optional()) {
      // A hand model's sizes in metres, or 0: not known to the writer (FitRow).
      for (auto [col, v] : {std::pair{c.col("length_m"), &r.length_m}, std::pair{c.col("width_m"), &r.width_m}}) {
        *v = c.number(col);
        if (!(*v == 0.0 || (*v > 0.0 && *v < 1.0)))
          c.fail(col, "expected a hand size in metres, in (0, 1), or 0 (not recorded), got " + std::string(c.text(col)));
      }
    }
    out.push_back(r);
  }
  if (!out.empty() && out.back().hand == 0)
    c.fail_line("the last frame has no row for hand 1 (the file is cut off)", c.line() + 1);
  return out;
}

double recorded_seconds(const std::string& dir) {
  for (const std::string_view file : {files::kFingertips, files::kFrames}) {
    const std::string column = file == files::kFrames ? "t_exposure_ns" : "t_ns";
    const fs::path path = fs::path(dir) / file;
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) continue;  // not a device or FIFO
    std::ifstream in(path, std::ios::binary);
    if (!in) continue;
    std::string header, row;
    if (!std::getline(in, header)) continue;
    if (!header.empty() && header.back() == '\r') header.pop_back();
    std::size_t index = 0;
    {
      std::stringstream names(header);
      std::string n;
      while (std::getline(names, n, ',') && n != column) ++index;
      if (n != column) continue;
    }
    bool any = false;
    std::int64_t first = 0, last = 0;
    while (std::getline(in, row) && !in.eof()) {  // a last row without a line end is cut off
      std::size_t start = 0;
      for (std::size_t k = 0; k < index && start != std::string::npos; ++k) {
        start = row.find(',', start);
        if (start != std::string::npos) ++start;
      }
      if (start == std::string::npos) break;
      char* end = nullptr;
      const long long t = std::strtoll(row.c_str() + start, &end, 10);
      if (end == row.c_str() + start || (*end != ',' && *end != '\r' && *end != '\0')) break;
      if (!any) first = t;
      last = t;
      any = true;
    }
    if (any) return static_cast<double>(last - first) * 1e-9;
  }
  return 0.0;
}

Recording read_recording(const std::string& dir) {
  const fs::path d(dir);
  const std::string session_path = (d / files::kSession).string();
  struct stat st {};
  if (::stat(session_path.c_str(), &st) != 0)
    throw core::FileError(dir, "no session.json (expected a folder written by run --record)");
  const SessionJson s = parse_session_json(core::read_file_bounded(session_path, 1 << 20, "a session.json"), session_path);
  if (!s.complete) {
    char secs[32];
    std::snprintf(secs, sizeof secs, "%.1f", recorded_seconds(dir));
    throw RecordingError(dir, 0, 0,
                         std::string("recording incomplete, ") + secs +
                             " s: session.json has no \"complete\": true (the recording was interrupted, or a "
                             "write failed, before it finished); replay needs a complete recording");
  }
  Recording r;
  r.dir = dir;
  r.meta = s.meta;
  r.rows = s.rows;
  r.config_path = (d / files::kConfig).string();
  if (::stat(r.config_path.c_str(), &st) != 0 || !S_ISREG(st.st_mode))
    throw core::FileError(r.config_path, "missing (the live config the session ran with)");

  const std::string device_path = (d / files::kDevice).string();
  {
    std::ifstream in = open_csv(device_path);
    r.device_rows = read_device_csv(in, device_path, r.meta.string_count);
    require_rows(device_path, static_cast<int>(std::min<std::uint64_t>(r.device_rows + 2, INT32_MAX)), r.device_rows,
                 r.rows.device, "device");
  }
  const std::string fingertips_path = (d / files::kFingertips).string();
  {
    std::ifstream in = open_csv(fingertips_path);
    r.fingertips = read_fingertips_csv(in, fingertips_path, r.meta.finger_count, r.meta.string_count);
    require_rows(fingertips_path, static_cast<int>(r.fingertips.size() + 2), r.fingertips.size(), r.rows.fingertips,
                 "fingertips");
  }
  const std::string frames_path = (d / files::kFrames).string();
  {
    std::ifstream in = open_csv(frames_path);
    // The frames' images: inside the folder and present (PNG), or numbered 0, 1, ... in the video.
    auto check_image = [&](std::size_t i, const std::string& image) -> std::string {
      if (r.meta.store != FrameStore::kPng)
        return image == std::to_string(i) ? "" : "expected video frame " + std::to_string(i);
      if (!inside(d, image))
        return "expected a path inside the recording folder (no '..', not absolute, no symbolic link leading out)";
      const std::string p = (d / image).string();
      if (::stat(p.c_str(), &st) != 0) return core::printable_for_message(p) + " is missing";
      if (S_ISDIR(st.st_mode)) return core::printable_for_message(p) + " is a directory, expected a PNG file";
      if (!S_ISREG(st.st_mode)) return core::printable_for_message(p) + " is not a regular file, expected a PNG file";
      return "";
    };
    r.frames = read_frames_csv(in, frames_path, r.meta.finger_count, check_image);
    require_rows(frames_path, static_cast<int>(r.frames.size() + 2), r.frames.size(), r.rows.frames, "frames");
  }
  if (r.meta.store != FrameStore::kPng) {
    r.video_path = (d / r.meta.frames_file).string();
    if (::stat(r.video_path.c_str(), &st) != 0 || !S_ISREG(st.st_mode))
      throw core::FileError(r.video_path, "missing (session.json frames_file: the camera video)");
  }

  const std::string scene_path = (d / files::kScene).string();
  {
    std::ifstream in = open_csv(scene_path);
    std::vector<std::int64_t> frames;
    auto groups = read_scene_csv(in, scene_path, &frames);
    std::uint64_t rows = 0;
    for (const auto& g : groups) rows += g.size();
    require_rows(scene_path, static_cast<int>(rows + 2), rows, r.rows.scene, "scene");
    r.scene.assign(r.frames.size(), {});
    const std::size_t shapes = groups.empty() ? 0 : groups[0].size();
    int line = 2;
    for (std::size_t k = 0; k < groups.size(); ++k) {
      if (frames[k] >= static_cast<std::int64_t>(r.frames.size()))
        throw RecordingError(scene_path, line, 1, "frame " + std::to_string(frames[k]) + " is not in frames.csv (" +
                                                      std::to_string(r.frames.size()) + " frames)");
      if (groups[k].size() != shapes)
        throw RecordingError(scene_path, line, 1, "frame " + std::to_string(frames[k]) + " has " +
                                                      std::to_string(groups[k].size()) + " shapes, frame " +
                                                      std::to_string(frames[0]) + " " + std::to_string(shapes));
      r.scene[static_cast<std::size_t>(frames[k])] = std::move(groups[k]);
      line += static_cast<int>(r.scene[static_cast<std::size_t>(frames[k])].size());
    }
    if (!groups.empty() && groups.size() != r.frames.size())
      throw RecordingError(scene_path, 0, 0, "poses for " + std::to_string(groups.size()) + " frames, frames.csv has " +
                                                 std::to_string(r.frames.size()));
  }
  const std::string fits_path = (d / files::kFits).string();
  {
    std::ifstream in = open_csv(fits_path);
    const auto rows = read_fits_csv(in, fits_path);
    require_rows(fits_path, static_cast<int>(rows.size() + 2), rows.size(), r.rows.fits, "fits");
    if (rows.size() != 2 * r.frames.size())
      throw RecordingError(fits_path, static_cast<int>(rows.size() + 2), 1,
                           std::to_string(rows.size()) + " rows, expected 2 per frame of frames.csv (" +
                               std::to_string(2 * r.frames.size()) + ")");
    r.fits.resize(r.frames.size());
    for (std::size_t i = 0; i < rows.size(); i += 2) {
      if (rows[i].frame != static_cast<std::int64_t>(i / 2))
        throw RecordingError(fits_path, static_cast<int>(i + 2), 1,
                             "frame " + std::to_string(rows[i].frame) + ", expected " + std::to_string(i / 2) +
                                 " (one pair of rows per frame of frames.csv, in order)");
      r.fits[i / 2] = {rows[i], rows[i + 1]};
    }
  }
  return r;
}

}  // namespace spidar::session
