// A recording written by RecordingWriter reads back equal, field by field, through
// read_recording; the writer's failures (a full disk, an existing recording) name the path.
#include <gtest/gtest.h>

#include "recording_test_support.hpp"
#include "spidar/session/recording_reader.hpp"

namespace {

using namespace spidar;
using namespace spidar::session;
using namespace spidar::session::testing;

void expect_same_sample(const device::FingertipSample& a, const device::FingertipSample& b) {
  EXPECT_EQ(a.t_ns, b.t_ns);
  EXPECT_EQ(a.faults, b.faults);
  EXPECT_EQ(a.consistent, b.consistent);
  EXPECT_EQ(a.finger_count, b.finger_count);
  EXPECT_EQ(a.p_W, b.p_W);  // bit for bit: 17 significant digits
  EXPECT_EQ(a.f_W, b.f_W);
}

void expect_reads_back(const TestRecording& t, const Recording& r) {
  EXPECT_EQ(r.meta.width, t.meta.width);
  EXPECT_EQ(r.meta.height, t.meta.height);
  EXPECT_EQ(r.meta.fps, t.meta.fps);
  EXPECT_EQ(r.meta.string_count, t.meta.string_count);
  EXPECT_EQ(r.meta.finger_count, t.meta.finger_count);
  EXPECT_EQ(r.meta.device_name, t.meta.device_name);
  EXPECT_EQ(r.meta.store, t.meta.store);
  EXPECT_EQ(r.meta.initial_r_W_hand[1], t.meta.initial_r_W_hand[1]);
  EXPECT_EQ(r.rows.device, t.device.size());
  EXPECT_EQ(r.rows.fingertips, t.fingertips.size());
  EXPECT_EQ(r.rows.frames, t.frames.size());
  EXPECT_EQ(r.rows.scene, 2 * t.frames.size());
  EXPECT_EQ(r.rows.fits, 2 * t.frames.size());
  EXPECT_DOUBLE_EQ(r.rows.seconds, 2.375);
  EXPECT_EQ(r.device_rows, t.device.size());
  ASSERT_EQ(r.fingertips.size(), t.fingertips.size());
  for (std::size_t k = 0; k < t.fingertips.size(); ++k) {
    expect_same_sample(r.fingertips[k], t.fingertips[k]);
    EXPECT_EQ(r.fingertips[k].cycle, t.fingertips[k].cycle);
    EXPECT_EQ(r.fingertips[k].string_count, t.meta.string_count);
    EXPECT_EQ(r.fingertips[k].tension, t.fingertips[k].tension);  // bit for bit
    EXPECT_EQ(r.fingertips[k].command, t.fingertips[k].command);
  }
  ASSERT_EQ(r.frames.size(), t.frames.size());
  for (std::size_t i = 0; i < t.frames.size(); ++i) {
    EXPECT_EQ(r.frames[i].index, t.frames[i].index);
    EXPECT_EQ(r.frames[i].t_exposure_ns, t.frames[i].t_exposure_ns);
    EXPECT_EQ(r.frames[i].image, t.frames[i].image);
    expect_same_sample(r.frames[i].measured, t.frames[i].measured);
    ASSERT_EQ(r.scene[i].size(), t.scene[i].size());
    for (std::size_t s = 0; s < t.scene[i].size(); ++s) {
      EXPECT_EQ(r.scene[i][s].p, t.scene[i][s].p);
      EXPECT_EQ(r.scene[i][s].R.coeffs(), t.scene[i][s].R.coeffs());
    }
    for (int h = 0; h < 2; ++h) {
      const FitRow& a = r.fits[i][static_cast<std::size_t>(h)];
      const FitRow& b = t.fits[i][static_cast<std::size_t>(h)];
      EXPECT_EQ(a.frame, b.frame);
      EXPECT_EQ(a.hand, b.hand);
      EXPECT_EQ(a.iterations, b.iterations);
      EXPECT_EQ(a.converged, b.converged);
      EXPECT_EQ(a.finite, b.finite);
      EXPECT_EQ(a.length_m, b.length_m);  // bit for bit, also for a fit that was not finite
      EXPECT_EQ(a.width_m, b.width_m);
      if (b.finite) {
        EXPECT_EQ(a.cost_initial, b.cost_initial);
        EXPECT_EQ(a.cost_final, b.cost_final);
        EXPECT_EQ(a.terms, b.terms);
        EXPECT_EQ(a.q, b.q);
      } else {
        EXPECT_TRUE(std::isnan(a.q[0]));  // not a number the replay could compare with
      }
    }
  }
}

TEST(RecordingRoundTrip, PngRecordingReadsBackEqual) {
  TempFolder d("roundtrip_png");
  const fs::path dir = d.path() / "rec";
  const TestRecording t = make_test_recording(FrameStore::kPng);
  write_test_recording(t, dir);
  const Recording r = read_recording(dir.string());
  expect_reads_back(t, r);
  EXPECT_EQ(r.config_path, (dir / "config.yaml").string());
  EXPECT_EQ(slurp(dir / "config.yaml"), "device_config: x.yaml\n");
  // The device rows as the reader parses them.
  std::ifstream in(dir / "device.csv");
  std::vector<DeviceCycleRecord> rows;
  read_device_csv(in, "device.csv", 3, [&](const DeviceCycleRecord& row) { rows.push_back(row); });
  ASSERT_EQ(rows.size(), t.device.size());
  for (std::size_t k = 0; k < rows.size(); ++k) {
    EXPECT_EQ(rows[k].seq, t.device[k].seq);
    EXPECT_EQ(rows[k].reading.host_time_ns, t.device[k].reading.host_time_ns);
    EXPECT_EQ(rows[k].reading.device_time_us, t.device[k].reading.device_time_us);
    EXPECT_EQ(rows[k].reading.status_flags, t.device[k].reading.status_flags);
    EXPECT_EQ(rows[k].reading.repeats, t.device[k].reading.repeats);
    EXPECT_EQ(rows[k].reading.counts, t.device[k].reading.counts);
    EXPECT_EQ(rows[k].commands, t.device[k].commands);
  }
}

TEST(RecordingRoundTrip, VideoRecordingReadsBackEqualAndNamesItsVideo) {
  TempFolder d("roundtrip_video");
  const fs::path dir = d.path() / "rec";
  const TestRecording t = make_test_recording(FrameStore::kMjpg);
  write_test_recording(t, dir);
  const Recording r = read_recording(dir.string());
  expect_reads_back(t, r);
  EXPECT_EQ(r.meta.frames_file, "camera.avi");
  EXPECT_EQ(r.meta.frames_codec, "avi/mjpg");
  EXPECT_EQ(r.video_path, (dir / "camera.avi").string());
}

TEST(RecordingRoundTrip, CsvColumnsInAnotherOrderAreFoundByName) {
  TempFolder d("by_name");
  const fs::path dir = d.path() / "rec";
  const TestRecording t = make_test_recording(FrameStore::kPng);
  write_test_recording(t, dir);
  // Swap the first two columns of scene.csv, header and rows alike.
  auto lines = lines_of(dir / "scene.csv");
  for (auto& l : lines) {
    const auto a = l.find(','), b = l.find(',', a + 1);
    l = l.substr(a + 1, b - a - 1) + "," + l.substr(0, a) + l.substr(b);
  }
  write_lines(dir / "scene.csv", lines);
  expect_reads_back(t, read_recording(dir.string()));
}

TEST(RecordingRoundTrip, CrlfFilesReadTheSame) {
  TempFolder d("crlf");
  const fs::path dir = d.path() / "rec";
  const TestRecording t = make_test_recording(FrameStore::kPng);
  write_test_recording(t, dir);
  for (const char* f : {"device.csv", "fingertips.csv", "frames.csv", "scene.csv", "fits.csv", "session.json"}) {
    std::string text;
    for (const auto& l : lines_of(dir / f)) text += l + "\r\n";
    spit(dir / f, text);
  }
  expect_reads_back(t, read_recording(dir.string()));
}

/// `file` in `dir` without its last `drop` columns (header and rows).
void drop_last_columns(const fs::path& dir, const std::string& file, int drop) {
  auto lines = lines_of(dir / file);
  for (auto& l : lines)
    for (int k = 0; k < drop; ++k) l.erase(l.rfind(','));
  write_lines(dir / file, lines);
}

/// Reading the recording in `dir` fails at line 1 of `file`, naming the missing `column`.
void expect_missing_column(const fs::path& dir, const std::string& file, const std::string& column) {
  try {
    read_recording(dir.string());
    ADD_FAILURE() << "a " << file << " without " << column << " was read";
  } catch (const RecordingError& e) {
    EXPECT_EQ(e.file(), (dir / file).string());
    EXPECT_EQ(e.line(), 1);
    EXPECT_NE(std::string(e.what()).find("no column '" + column + "'"), std::string::npos) << e.what();
  }
}

// A version-2 recording made before fingertips.csv had the servo's outputs still reads: its
// samples have no strings; one with only some of those columns is refused naming the missing one.
TEST(RecordingRoundTrip, ServoOutputColumnsAreOptionalButAllOrNone) {
  TempFolder d("servo_outputs");
  const fs::path dir = d.path() / "rec";
  const TestRecording t = make_test_recording(FrameStore::kPng);
  write_test_recording(t, dir);
  EXPECT_NE(lines_of(dir / "fingertips.csv").front().find(",tension0,tension1,tension2,motor0,motor1,motor2"),
            std::string::npos);
  drop_last_columns(dir, "fingertips.csv", 1);
  expect_missing_column(dir, "fingertips.csv", "motor2");
  drop_last_columns(dir, "fingertips.csv", 5);  // the rest: as written before the columns existed
  const Recording r = read_recording(dir.string());
  ASSERT_EQ(r.fingertips.size(), t.fingertips.size());
  for (std::size_t k = 0; k < t.fingertips.size(); ++k) {
    expect_same_sample(r.fingertips[k], t.fingertips[k]);
    EXPECT_EQ(r.fingertips[k].string_count, 0);
    EXPECT_EQ(r.fingertips[k].tension[0], 0.0);
  }
}

// fits.csv's hand sizes (length_m, width_m) likewise: a recording made before them reads with
// sizes 0 (not recorded), one with only one of them is refused naming the other.
TEST(RecordingRoundTrip, FitSizeColumnsAreOptionalButAllOrNone) {
  TempFolder d("fit_sizes");
  const fs::path dir = d.path() / "rec";
  const TestRecording t = make_test_recording(FrameStore::kPng);
  write_test_recording(t, dir);
  ASSERT_NE(lines_of(dir / "fits.csv").front().find(",q16,length_m,width_m"), std::string::npos);
  drop_last_columns(dir, "fits.csv", 1);
  expect_missing_column(dir, "fits.csv", "width_m");
  drop_last_columns(dir, "fits.csv", 1);  // length_m too: as written before the columns existed
  const Recording r = read_recording(dir.string());
  ASSERT_EQ(r.fits.size(), t.fits.size());
  for (const auto& frame : r.fits)
    for (const FitRow& f : frame) {
      EXPECT_EQ(f.length_m, 0.0);
      EXPECT_EQ(f.width_m, 0.0);
    }
  EXPECT_EQ(r.fits[2][1].q, t.fits[2][1].q);
}

// What the reader refuses as damage, the writer never writes: a diverged fit (a cost of 1e13, a
// joint of 1e4 rad) is marked not finite, a fingertip solved 1 km away is saturated at the bound.
TEST(RecordingWriter, ARunsOwnRecordingStaysReadableWhateverItsNumbers) {
  TempFolder d("bounds");
  const fs::path dir = d.path() / "rec";
  TestRecording t = make_test_recording(FrameStore::kPng);
  t.fits[1][0].cost_final = 1e13;
  t.fits[2][1].q[7] = -1e4;
  t.fingertips[3].p_W[1][2] = -1000.0;
  t.fingertips[4].f_W[0][0] = 1e9;
  t.scene[0][0].p = Vec3(5e3, 0, 0);
  write_test_recording(t, dir);
  const Recording r = read_recording(dir.string());
  EXPECT_FALSE(r.fits[1][0].finite);
  EXPECT_TRUE(std::isnan(r.fits[1][0].cost_final));
  EXPECT_FALSE(r.fits[2][1].finite);
  EXPECT_TRUE(r.fits[2][0].finite);  // the other hand's fit of that frame is kept
  EXPECT_EQ(r.fingertips[3].p_W[1][2], -recording_bounds::kPosition_m);
  EXPECT_EQ(r.fingertips[4].f_W[0][0], recording_bounds::kForce_N);
  EXPECT_EQ(r.scene[0][0].p.x(), recording_bounds::kPosition_m);
}

TEST(RecordingWriter, RefusesAFolderHoldingARecording) {
  TempFolder d("twice");
  const TestRecording t = make_test_recording(FrameStore::kPng);
  write_test_recording(t, d.path() / "rec");
  try {
    RecordingWriter w((d.path() / "rec").string(), t.meta, "");
    FAIL() << "a second recording into the same folder";
  } catch (const SpidarError& e) {
    EXPECT_NE(std::string(e.what()).find("already holds a recording"), std::string::npos) << e.what();
  }
}

TEST(RecordingWriter, ANewRecordingGoesOnlyIntoANewOrEmptyFolder) {
  TempFolder d("notempty");
  const fs::path dir = d.path() / "mine";
  fs::create_directories(dir);
  { std::ofstream(dir / "config.yaml") << "my own notes\n"; }
  try {
    check_new_recording_folder(dir.string());
    FAIL() << "a recording into a folder holding other files";
  } catch (const SpidarError& e) {
    EXPECT_NE(std::string(e.what()).find("is not empty (it holds config.yaml)"), std::string::npos) << e.what();
  }
  { std::ofstream(d.path() / "a_file") << "x"; }
  EXPECT_THROW(check_new_recording_folder((d.path() / "a_file").string()), SpidarError);
  // A folder that does not exist yet, or an empty one (made beforehand, e.g. by mktemp -d), is fine.
  EXPECT_NO_THROW(check_new_recording_folder((d.path() / "new").string()));
  fs::create_directories(d.path() / "empty");
  EXPECT_NO_THROW(check_new_recording_folder((d.path() / "empty").string()));
  // A recording is named as one.
  const TestRecording t = make_test_recording(FrameStore::kPng);
  write_test_recording(t, d.path() / "rec");
  try {
    check_new_recording_folder((d.path() / "rec").string());
    FAIL() << "a second recording into the same folder";
  } catch (const SpidarError& e) {
    EXPECT_NE(std::string(e.what()).find("already holds a recording"), std::string::npos) << e.what();
  }
}

TEST(RecordingWriter, AFullDiskFailsNamingTheFileAndLeavesNoCompletionMarker) {
  TempFolder d("full");
  const fs::path dir = d.path() / "rec";
  fs::create_directories(dir);
  fs::create_symlink("/dev/full", dir / "fingertips.csv");  // every write fails with ENOSPC
  const TestRecording t = make_test_recording(FrameStore::kPng);
  RecordingWriter w(dir.string(), t.meta, "");
  bool failed_early = false;
  for (int k = 0; k < 5000 && !failed_early; ++k) failed_early = !w.write_fingertip(t.fingertips[0]);
  EXPECT_TRUE(failed_early) << "a 64 KiB buffer fills within 5000 rows and its write fails";
  EXPECT_NE(w.error().find("fingertips.csv: write failed: No space left on device"), std::string::npos) << w.error();
  try {
    w.finish();
    FAIL() << "finish() succeeded on a full disk";
  } catch (const SpidarError& e) {
    EXPECT_NE(std::string(e.what()).find((dir / "fingertips.csv").string() + ": write failed"), std::string::npos)
        << e.what();
  }
  const auto s = parse_session_json(slurp(dir / "session.json"), "session.json");
  EXPECT_FALSE(s.complete);
  try {
    (void)read_recording(dir.string());
    FAIL() << "an incomplete recording was read";
  } catch (const RecordingError& e) {
    EXPECT_NE(std::string(e.what()).find("incomplete"), std::string::npos) << e.what();
  }
}

TEST(RecordingWriter, CloseIncompleteKeepsTheRowsWithoutTheMarker) {
  // A recording that failed elsewhere (a frame image not written): the rows are flushed so that
  // replay can say how long it is, but it is not complete.
  TempFolder d("incomplete");
  const fs::path dir = d.path() / "rec";
  const TestRecording t = make_test_recording(FrameStore::kPng);
  RecordingWriter w(dir.string(), t.meta, "");
  for (const auto& s : t.fingertips) ASSERT_TRUE(w.write_fingertip(s));
  w.close_incomplete();
  EXPECT_EQ(lines_of(dir / "fingertips.csv").size(), t.fingertips.size() + 1);
  EXPECT_FALSE(parse_session_json(slurp(dir / "session.json"), "session.json").complete);
  EXPECT_DOUBLE_EQ(recorded_seconds(dir.string()), 2.375);
}

TEST(RecordingWriter, AFullDiskAtCloseFailsToo) {
  // Fewer rows than the buffer holds: nothing is written before finish(), whose flush fails.
  TempFolder d("full_close");
  const fs::path dir = d.path() / "rec";
  fs::create_directories(dir);
  fs::create_symlink("/dev/full", dir / "fits.csv");
  const TestRecording t = make_test_recording(FrameStore::kPng);
  RecordingWriter w(dir.string(), t.meta, "");
  EXPECT_TRUE(w.write_fingertip(t.fingertips[0]));
  EXPECT_THROW(w.finish(), SpidarError);
  EXPECT_FALSE(parse_session_json(slurp(dir / "session.json"), "session.json").complete);
}

}  // namespace
