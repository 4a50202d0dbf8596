// Damaged recordings are refused with FILE:LINE:COLUMN and what was expected: each kind of damage
// made by hand on a recording written by RecordingWriter.
#include <gtest/gtest.h>

#include <algorithm>

#include <sys/stat.h>

#include "recording_test_support.hpp"
#include "spidar/session/recording_reader.hpp"

namespace {

using namespace spidar;
using namespace spidar::session;
using namespace spidar::session::testing;

/// A fresh, valid PNG recording for each test.
class Damage : public ::testing::Test {
 protected:
  Damage() : tmp_(::testing::UnitTest::GetInstance()->current_test_info()->name()) {
    dir_ = tmp_.path() / "rec";
    write_test_recording(make_test_recording(FrameStore::kPng), dir_);
  }
  /// read_recording's error message; fails the test if it read without error.
  std::string refusal() {
    try {
      (void)read_recording(dir_.string());
    } catch (const SpidarError& e) {
      return e.what();
    }
    ADD_FAILURE() << "the damaged recording was read without error";
    return "";
  }
  std::string where(const char* file, int line, int column) const {
    return (dir_ / file).string() + ":" + std::to_string(line) + ":" + std::to_string(column) + ": ";
  }
  TempFolder tmp_;
  fs::path dir_;
};

#define EXPECT_HAS(haystack, needle) EXPECT_NE((haystack).find(needle), std::string::npos) << (haystack)

TEST_F(Damage, ADeletedFileIsNamed) {
  fs::remove(dir_ / "device.csv");
  const std::string e = refusal();
  EXPECT_HAS(e, (dir_ / "device.csv").string() + ": missing");
}

TEST_F(Damage, ATruncatedLastRowIsCutOff) {
  std::string text = slurp(dir_ / "device.csv");
  text.resize(text.size() - 7);  // into the last row (line 21: a header and 20 rows)
  spit(dir_ / "device.csv", text);
  const std::string e = refusal();
  EXPECT_HAS(e, where("device.csv", 21, 1) + "the last row is cut off");
}

TEST_F(Damage, ARowWithFewerFieldsIsNamed) {
  auto lines = lines_of(dir_ / "fingertips.csv");
  lines[4] = lines[4].substr(0, lines[4].find(',', lines[4].find(',') + 1));  // line 5: 2 fields
  write_lines(dir_ / "fingertips.csv", lines);
  const std::string e = refusal();
  // 53 sample columns and the servo outputs of 3 strings (tension0..2, motor0..2).
  EXPECT_HAS(e, where("fingertips.csv", 5, static_cast<int>(lines[4].size()) + 1) + "2 fields, expected 59");
}

TEST_F(Damage, AGarbageNumberIsNamedWithItsColumn) {
  const int col = set_field(dir_ / "device.csv", 4, 6, "12x4");  // count1 of the 3rd row
  const std::string e = refusal();
  EXPECT_HAS(e, where("device.csv", 4, col) + "count1: expected an integer");
  EXPECT_HAS(e, "got '12x4'");
}

TEST_F(Damage, NanIsRefused) {
  const int col = set_field(dir_ / "fingertips.csv", 3, 6, "nan");  // p0y
  const std::string e = refusal();
  EXPECT_HAS(e, where("fingertips.csv", 3, col) + "p0y: expected a finite number, got 'nan'");
}

TEST_F(Damage, NanInAFitMarkedFiniteIsRefused) {
  const int col = set_field(dir_ / "fits.csv", 2, 12, "nan");  // q0 of frame 0, hand 0
  const std::string e = refusal();
  EXPECT_HAS(e, where("fits.csv", 2, col) + "q0: expected a finite number, got 'nan'");
}

// A finite number too large for what it is (1e308 for a position) would overflow what replay
// computes from it (inf in its report): refused at its column with the range.
TEST_F(Damage, AHugeFiniteNumberIsRefusedWithTheRange) {
  const int col = set_field(dir_ / "fingertips.csv", 3, 6, "1e308");  // p0y
  const std::string e = refusal();
  EXPECT_HAS(e, where("fingertips.csv", 3, col) + "p0y: expected a fingertip coordinate [m] from -100 to 100, got '1e308'");
}

TEST_F(Damage, AHugePoseParameterInAFitIsRefused) {
  const int col = set_field(dir_ / "fits.csv", 2, 12, "-1e300");  // q0 of frame 0, hand 0
  const std::string e = refusal();
  EXPECT_HAS(e, where("fits.csv", 2, col) + "q0: expected a pose parameter [m or rad] from -1000 to 1000, got '-1e300'");
}

TEST_F(Damage, AWrongHeaderIsNamed) {
  const int col = set_field(dir_ / "fingertips.csv", 1, 5, "p0_x");
  const std::string e = refusal();
  EXPECT_HAS(e, where("fingertips.csv", 1, col) + "unknown column 'p0_x'");
  EXPECT_HAS(e, "version-2 recording");
}

TEST_F(Damage, ANestedKeyIsNamedWithItsPath) {
  std::string text = slurp(dir_ / "session.json");
  const auto rows = text.find("\"rows\"");
  ASSERT_NE(rows, std::string::npos);
  const auto frames = text.find("\"frames\":", rows);
  ASSERT_NE(frames, std::string::npos);
  text.replace(frames, 9, "\"frames\": 1e18, \"was\":");
  spit(dir_ / "session.json", text);
  EXPECT_HAS(refusal(), (dir_ / "session.json").string() + ": key \"rows.frames\": expected an integer");
}

TEST_F(Damage, AnotherVersionIsRefusedSayingWhichOne) {
  std::string text = slurp(dir_ / "session.json");
  text.replace(text.find("\"version\": 2"), 12, "\"version\": 1");
  spit(dir_ / "session.json", text);
  const std::string e = refusal();
  EXPECT_HAS(e, (dir_ / "session.json").string() + ": key \"version\": this recording has format version 1");
  EXPECT_HAS(e, "reads version 2");
}

TEST_F(Damage, FramesInReverseOrderAreRefused) {
  auto lines = lines_of(dir_ / "frames.csv");
  std::reverse(lines.begin() + 1, lines.end());
  write_lines(dir_ / "frames.csv", lines);
  const std::string e = refusal();
  EXPECT_HAS(e, where("frames.csv", 2, 1) + "frame: expected frame 0");
}

TEST_F(Damage, TimeGoingBackIsRefused) {
  const auto lines = lines_of(dir_ / "device.csv");
  const std::string earlier = lines[3].substr(lines[3].find(',') + 1, lines[3].find(',', lines[3].find(',') + 1) - lines[3].find(',') - 1);
  const int col = set_field(dir_ / "device.csv", 6, 1, earlier);  // line 6 gets line 4's time
  const std::string e = refusal();
  EXPECT_HAS(e, where("device.csv", 6, col) + "host_time_ns: time goes back");
}

TEST_F(Damage, ARowCountDisagreeingWithSessionJsonIsRefused) {
  auto lines = lines_of(dir_ / "fingertips.csv");
  lines.pop_back();  // a whole row less: 19 rows
  write_lines(dir_ / "fingertips.csv", lines);
  const std::string e = refusal();
  EXPECT_HAS(e, where("fingertips.csv", 21, 1) + "19 rows, but session.json says 20 (rows.fingertips)");
}

TEST_F(Damage, ANonUnitQuaternionIsRefused) {
  const int col = set_field(dir_ / "scene.csv", 3, 5, "2");  // qw of frame 0, shape 1
  const std::string e = refusal();
  EXPECT_HAS(e, where("scene.csv", 3, col) + "qw: the orientation quaternion has norm");
  EXPECT_HAS(e, "expected a unit quaternion");
}

TEST_F(Damage, AnImagePathOutsideTheRecordingIsRefused) {
  for (const std::string bad : {"../../etc/passwd", "/etc/passwd", "frames/../../x.png"}) {
    SCOPED_TRACE(bad);
    write_test_recording(make_test_recording(FrameStore::kPng), tmp_.path() / ("r" + std::to_string(bad.size())));
    dir_ = tmp_.path() / ("r" + std::to_string(bad.size()));
    const int col = set_field(dir_ / "frames.csv", 3, 2, bad);
    const std::string e = refusal();
    EXPECT_HAS(e, where("frames.csv", 3, col) + "image: expected a path inside the recording folder");
  }
  // A symbolic link out of the folder, too.
  fs::remove(dir_ / "frames/000001.png");
  fs::create_symlink("/etc/hostname", dir_ / "frames/000001.png");
  set_field(dir_ / "frames.csv", 3, 2, "frames/000001.png");
  EXPECT_HAS(refusal(), "image: expected a path inside the recording folder");
}

TEST_F(Damage, AMissingImageIsNamed) {
  fs::remove(dir_ / "frames/000002.png");
  const std::string e = refusal();
  EXPECT_HAS(e, where("frames.csv", 4, column_of(lines_of(dir_ / "frames.csv")[3], 2)) + "image: ");
  EXPECT_HAS(e, "000002.png is missing");
}

// A spreadsheet's "CSV UTF-8" starts with a byte-order mark: not part of the first column's name.
TEST(CsvWithAByteOrderMark, IsReadAsWithout) {
  TempFolder tmp("csv_bom");
  const fs::path dir = tmp.path() / "rec";
  write_test_recording(make_test_recording(FrameStore::kPng), dir);
  const Recording plain = read_recording(dir.string());
  for (const char* file : {"frames.csv", "fingertips.csv", "fits.csv", "scene.csv"})
    spit(dir / file, "\xEF\xBB\xBF" + slurp(dir / file));
  const Recording marked = read_recording(dir.string());
  EXPECT_EQ(marked.frames.size(), plain.frames.size());
  EXPECT_EQ(marked.fingertips.size(), plain.fingertips.size());
  EXPECT_EQ(marked.scene.size(), plain.scene.size());
  ASSERT_FALSE(marked.frames.empty());
  EXPECT_EQ(marked.frames.back().measured.p_W[1][2], plain.frames.back().measured.p_W[1][2]);
  // A damaged header after the mark: its column counts the mark's three bytes, as the file holds them.
  const int col = set_field(dir / "fingertips.csv", 1, 5, "p0_x");
  try {
    (void)read_recording(dir.string());
    FAIL() << "an unknown column after a byte-order mark was read";
  } catch (const RecordingError& e) {
    const std::string at = (dir / "fingertips.csv").string() + ":1:" + std::to_string(col) + ": ";
    EXPECT_NE(std::string(e.what()).find(at + "unknown column 'p0_x'"), std::string::npos) << e.what();
  }
}

TEST_F(Damage, ADirectoryOrAFifoInPlaceOfAnImageIsNamedForWhatItIs) {
  fs::remove(dir_ / "frames/000002.png");
  fs::create_directory(dir_ / "frames/000002.png");
  EXPECT_HAS(refusal(), "000002.png is a directory, expected a PNG file");
  fs::remove(dir_ / "frames/000002.png");
  ASSERT_EQ(::mkfifo((dir_ / "frames/000002.png").c_str(), 0600), 0);
  EXPECT_HAS(refusal(), "000002.png is not a regular file, expected a PNG file");
}

TEST_F(Damage, ARecordingWithoutItsCompletionMarkerIsIncomplete) {
  std::string text = slurp(dir_ / "session.json");
  text.replace(text.find("\"complete\": true"), 16, "\"complete\": false");
  spit(dir_ / "session.json", text);
  const std::string e = refusal();
  EXPECT_HAS(e, dir_.string() + ": recording incomplete, 2.4 s");  // 20 samples 125 ms apart
}

TEST_F(Damage, AnInterruptedRecordingSaysHowManySecondsItHolds) {
  // As a killed `run --record` leaves it: the first session.json, a last row cut off.
  std::string text = slurp(dir_ / "session.json");
  text.replace(text.find("\"complete\": true"), 16, "\"complete\": false");
  spit(dir_ / "session.json", text);
  auto lines = lines_of(dir_ / "fingertips.csv");
  lines.resize(9);  // the header and 8 rows: 7 × 125 ms
  std::string cut;
  for (const auto& l : lines) cut += l + "\n";
  cut += "123456";  // a row cut off
  spit(dir_ / "fingertips.csv", cut);
  EXPECT_HAS(refusal(), "recording incomplete, 0.9 s");
}

TEST_F(Damage, BadSessionJsonIsNamed) {
  spit(dir_ / "session.json", "{\n  \"format\": \"spidar-mr recording\",\n  oops\n}\n");
  EXPECT_HAS(refusal(), (dir_ / "session.json").string() + ":3:3: not valid JSON");
  spit(dir_ / "session.json", "{\"format\": 3}");
  EXPECT_HAS(refusal(), (dir_ / "session.json").string() + ": key \"format\": expected \"spidar-mr recording\"");
  write_test_recording(make_test_recording(FrameStore::kPng), tmp_.path() / "again");
  dir_ = tmp_.path() / "again";
  std::string text = slurp(dir_ / "session.json");
  text.replace(text.find("\"finger_count\": 2"), 17, "\"finger_count\": 3");
  spit(dir_ / "session.json", text);
  EXPECT_HAS(refusal(), "finger_count: expected 3 (session.json finger_count), got 2");
}

// A number beyond a double's range is a damaged file (exit 2, its line and column), not an
// internal error.
TEST_F(Damage, ANumberBeyondADoublesRangeIsNamedWithItsPlace) {
  std::string text = slurp(dir_ / "session.json");
  const std::size_t at = text.find("\"fps\": ");
  ASSERT_NE(at, std::string::npos);
  const std::size_t value = at + 7, end = text.find_first_of(",\n}", value);
  text.replace(value, end - value, "1e999");
  spit(dir_ / "session.json", text);
  const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(value), '\n'));
  const int column = static_cast<int>(value - text.rfind('\n', value - 1));
  EXPECT_HAS(refusal(), (dir_ / "session.json").string() + ":" + std::to_string(line) + ":" +
                            std::to_string(column) + ": a number out of range ('1e999')");
}

TEST_F(Damage, AFitRowMarkedNotFiniteMustHaveNoNumbers) {
  // Frame 3, hand 1 was written as not finite (line 2 + 2·3 + 1 = 9): its numbers are empty.
  const int col = set_field(dir_ / "fits.csv", 9, 14, "0.5");  // q2
  EXPECT_HAS(refusal(), where("fits.csv", 9, col) + "q2: expected an empty field");
}

TEST_F(Damage, AHandSizeOutsideMetresIsNamed) {
  // fits.csv: 12 fields, q0..q16, then length_m (index 29) and width_m (30); line 4 = frame 1, hand 0.
  const int col = set_field(dir_ / "fits.csv", 4, 29, "190");  // millimetres, not metres
  EXPECT_HAS(refusal(), where("fits.csv", 4, col) + "length_m: expected a hand size in metres, in (0, 1), or 0 (not recorded), got 190");
  set_field(dir_ / "fits.csv", 4, 29, "0.19");
  const int wc = set_field(dir_ / "fits.csv", 4, 30, "-0.085");
  EXPECT_HAS(refusal(), where("fits.csv", 4, wc) + "width_m: expected a hand size in metres, in (0, 1), or 0 (not recorded), got -0.085");
}

}  // namespace
