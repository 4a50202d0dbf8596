// The run report's figures (session/run_report.hpp) from a hand-made trace: frames in which
// neither a real nor a fitted hand was in the camera's view say nothing about the fit, and are left
// out of the image's figures, said so, and counted.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>
#include <unistd.h>

#include "spidar/session/json_text.hpp"
#include "spidar/session/run_report.hpp"

namespace spidar::session {
namespace {

namespace fs = std::filesystem;

MrFrame frame(double t, double iou, double joints_px, long real_px, long fitted_px, bool compared,
              double ceiling) {
  MrFrame m;
  m.t_s = t;
  for (auto& k : m.truth) {
    k.iou = iou;
    k.joint_px = {joints_px, joints_px};
    k.fingertip_mm = {0.5, 0.5};
    k.real_hand_pixels = real_px;
    k.fitted_hand_pixels = fitted_px;
  }
  m.compared = compared;
  m.ceiling_measured = compared;
  m.ceiling_iou = ceiling;
  return m;
}

/// Writes the report of `t` into a fresh directory named for `tag`, and returns its report.json
/// (null if none was written) and the summary printed (into `*printed`).
nlohmann::json report_of(const MrTrace& t, double seconds, const std::string& tag, std::string* printed,
                         std::string* frames_csv = nullptr, MrSummary s = {}) {
  s.seconds = s.wall_s = seconds;
  const fs::path dir = fs::temp_directory_path() / ("spidar_run_report_" + tag + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ostringstream out;
  write_mr_report(dir.string(), t, s, out);
  *printed = out.str();
  std::ifstream in(dir / "report.json");
  nlohmann::json j = in.good() ? nlohmann::json::parse(in) : nlohmann::json();
  if (frames_csv) {
    std::ifstream csv(dir / "frames.csv");
    std::ostringstream text;
    text << csv.rdbuf();
    *frames_csv = text.str();
  }
  fs::remove_all(dir);
  return j;
}

// Text that is not UTF-8 (a path from the command line) is written with U+FFFD for its bad bytes:
// nlohmann's dump() would throw and lose a finished run's report.
TEST(JsonText, BytesThatAreNotUtf8BecomeTheReplacementCharacter) {
  nlohmann::json j;
  j["out"] = std::string("/tmp/run\xFF\xFE");
  j["device"] = "SPIDAR-8 \xC3\xA9";
  EXPECT_THROW((void)j.dump(), nlohmann::json::type_error);
  const std::string text = session::json_text(j);
  EXPECT_EQ(text, "{\"device\":\"SPIDAR-8 \xC3\xA9\",\"out\":\"/tmp/run\xEF\xBF\xBD\xEF\xBF\xBD\"}");
  EXPECT_EQ(nlohmann::json::parse(text)["device"], "SPIDAR-8 \xC3\xA9");
  EXPECT_EQ(session::json_text(nlohmann::json{{"a", 1}}, 2), "{\n  \"a\": 1\n}");
}

// Without a cube the report says how the reached-for object was held: its lift over the run and
// over the twist's frames (where the script holds it up), which a lost grip pulls down. With a
// cube there is no such section (the cube's own figures say it).
TEST(RunReport, WithoutACubeTheHeldObjectsLiftIsReportedOverTheTwist) {
  MrTrace t;
  MrSummary s;
  const std::pair<const char*, double> frames[] = {{"reach", 0.0}, {"lift", 6.0},  {"twist", 12.0}, {"twist", 11.0},
                                                   {"twist", 2.0},  {"twist", 10.0}, {"release", 14.0}, {"withdraw", 0.5}};
  for (const auto& [phase, lift] : frames) {
    MrFrame m = frame(0.1 * static_cast<double>(t.frames.size()), 0.8, 4.0, 900, 800, false, 0);
    m.lift_mm = lift;
    t.frames.push_back(m);
    s.phases.emplace_back(phase);
  }
  std::string printed, csv;
  s.has_cube = false;
  const auto j = report_of(t, 0.8, "object", &printed, &csv, s);
  ASSERT_TRUE(j.contains("object")) << j.dump();
  EXPECT_DOUBLE_EQ(j["object"]["lift_mm_max"].get<double>(), 14.0);
  EXPECT_DOUBLE_EQ(j["object"]["lift_mm_twist_median"].get<double>(), 10.5);  // of 2, 10, 11, 12
  EXPECT_EQ(j["object"]["twist_frames"].get<int>(), 4);
  EXPECT_LT(j["object"]["lift_mm_twist_p5"].get<double>(), 4.0);  // the frame where it slipped
  EXPECT_NE(csv.find(",12,"), std::string::npos) << csv;          // frames.csv's lift_mm column
  EXPECT_NE(printed.find("object         lifted 14.0 mm at most; over the twist (4 frames) 10.5 mm"),
            std::string::npos) << printed;
  s.has_cube = true;
  EXPECT_FALSE(report_of(t, 0.8, "cube", &printed, nullptr, s).contains("object"));
}

TEST(RunReport, FramesWithoutAHandInViewAreLeftOutOfTheImagesFigures) {
  MrTrace t;
  t.frames.push_back(frame(0.0, 0.8, 4.0, 900, 800, true, 0.9));
  t.frames.push_back(frame(0.1, 0.6, 6.0, 700, 900, false, 0));
  // The hands out of view: two empty masks (IoU 1 by convention), no joint in the image.
  t.frames.push_back(frame(0.2, 1.0, 0.0, 0, 0, true, 1.0));
  // A fit drawn where no real hand is: a real failure, scored (IoU 0); the ceiling, whose model is
  // at the true pose, has nothing to cover and is left out.
  t.frames.push_back(frame(0.3, 0.0, 30.0, 0, 500, true, 1.0));
  std::string printed;
  const auto j = report_of(t, 0.4, "images", &printed);
  ASSERT_FALSE(j.is_null()) << printed;
  const auto& reg = j["registration"];
  EXPECT_EQ(reg["frames"].get<int>(), 4);
  EXPECT_EQ(reg["frames_scored_in_image"].get<int>(), 3);
  EXPECT_NEAR(reg["iou_mean"].get<double>(), (0.8 + 0.6 + 0.0) / 3, 1e-12);
  EXPECT_NEAR(reg["joint_px_mean"].get<double>(), (4.0 + 6.0 + 30.0) / 3, 1e-12);
  EXPECT_NEAR(reg["fingertip_mm_mean"].get<double>(), 0.5, 1e-12);  // the strings see every frame
  EXPECT_NEAR(j["ground_truth"]["model_ceiling_iou"].get<double>(), 0.9, 1e-12);
  EXPECT_EQ(j["ground_truth"]["model_ceiling_frames"].get<int>(), 1);
  EXPECT_NE(printed.find("out of the camera's view in 1 frames"), std::string::npos) << printed;
}

// Where the IoU is lost: per-frame means per hand over the scored frames, and like for like (the
// fit and the ceiling) over the frames where the ceiling was measured.
TEST(RunReport, TheIousLossIsAveragedPerHandAndPartBesideTheCeilings) {
  MrTrace t;
  auto loss = [](long missed_left, long spill_palm_right, long both) {
    sim::SilhouetteLoss l;
    l.missed_palm = {missed_left, 0};
    l.missed_digits = {0, 3};
    l.spill_palm = {0, spill_palm_right};
    l.spill_digits = {5, 7};
    l.both = both;
    return l;
  };
  t.frames.push_back(frame(0.0, 0.8, 4.0, 900, 800, true, 0.9));
  t.frames.back().truth[0].loss = loss(100, 40, 800);
  t.frames.back().ceiling_loss = loss(60, 10, 850);
  t.frames.push_back(frame(0.1, 0.7, 5.0, 900, 800, false, 0));
  t.frames.back().truth[0].loss = loss(300, 80, 700);
  t.frames.push_back(frame(0.2, 1.0, 0.0, 0, 0, true, 1.0));  // out of view: not scored
  t.frames.back().truth[0].loss = loss(9999, 9999, 0);
  std::string printed;
  const auto j = report_of(t, 0.3, "loss", &printed);
  ASSERT_FALSE(j.is_null()) << printed;
  const auto& all = j["registration"]["silhouette_loss"];
  EXPECT_EQ(all["frames"].get<int>(), 2);
  EXPECT_DOUBLE_EQ(all["left"]["missed_palm_px"].get<double>(), 200.0);
  EXPECT_DOUBLE_EQ(all["right"]["missed_digits_px"].get<double>(), 3.0);
  EXPECT_DOUBLE_EQ(all["right"]["spill_palm_px"].get<double>(), 60.0);
  EXPECT_DOUBLE_EQ(all["right"]["spill_digits_px"].get<double>(), 7.0);
  EXPECT_DOUBLE_EQ(all["right"]["missed_palm_px"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(all["iou_pooled"].get<double>(), 1500.0 / (1500.0 + 400 + 6 + 120 + 24));
  const auto& same = j["registration"]["silhouette_loss_on_ceiling_frames"];
  EXPECT_EQ(same["frames"].get<int>(), 1);
  EXPECT_DOUBLE_EQ(same["left"]["missed_palm_px"].get<double>(), 100.0);
  const auto& ceiling = j["ground_truth"]["model_ceiling_loss"];
  EXPECT_EQ(ceiling["frames"].get<int>(), 1);
  EXPECT_DOUBLE_EQ(ceiling["left"]["missed_palm_px"].get<double>(), 60.0);
  EXPECT_DOUBLE_EQ(ceiling["right"]["spill_palm_px"].get<double>(), 10.0);
  EXPECT_NE(printed.find("fit      palm missed 100/0, spilled 0/40; digits missed 0/3, spilled 5/7\n"
                           "                   ceiling  palm missed 60/0, spilled 0/10"),
            std::string::npos)
      << printed;
}

// No hand in view in any frame (a camera turned away): the summary says so instead of an IoU of
// an empty set of frames (it printed "IoU mean 0.000", "joints 0.00 px").
TEST(RunReport, NoHandInViewIsSaidInsteadOfAnIou) {
  MrTrace t;
  for (int i = 0; i < 3; ++i) t.frames.push_back(frame(0.1 * i, 1.0, 0.0, 0, 0, false, 0));
  std::string printed;
  const auto j = report_of(t, 0.3, "none_in_view", &printed);
  ASSERT_FALSE(j.is_null()) << printed;
  EXPECT_EQ(j["registration"]["frames_scored_in_image"].get<int>(), 0);
  EXPECT_NE(printed.find("registration   IoU n/a, joints n/a (no hand in view in any frame), fingertip"),
            std::string::npos)
      << printed;
  EXPECT_EQ(printed.find("IoU mean 0.000"), std::string::npos) << printed;
}

// The wrists' image error: both hands of the scored frames, a wrist behind the camera (NaN) left out.
TEST(RunReport, TheWristsImageErrorIsAveragedOverTheWristsInView) {
  MrTrace t;
  t.frames.push_back(frame(0.0, 0.8, 4.0, 900, 800, false, 0));
  t.frames.back().truth[0].wrist_px = {2.0, 4.0};
  t.frames.push_back(frame(0.1, 0.8, 4.0, 900, 800, false, 0));
  t.frames.back().truth[0].wrist_px = {std::nan(""), 9.0};
  t.frames.push_back(frame(0.2, 1.0, 0.0, 0, 0, false, 0));  // out of view: not scored
  t.frames.back().truth[0].wrist_px = {100.0, 100.0};
  std::string printed, csv;
  const auto j = report_of(t, 0.3, "wrist", &printed, &csv);
  ASSERT_FALSE(j.is_null()) << printed;
  EXPECT_DOUBLE_EQ(j["registration"]["wrist_px_mean"].get<double>(), 5.0);
  // frames.csv leaves the wrist behind the camera empty, as its other missing values, not "nan".
  EXPECT_EQ(csv.find("nan"), std::string::npos) << csv;
  std::istringstream lines(csv);
  std::string header, first, second;
  std::getline(lines, header);
  std::getline(lines, first);
  std::getline(lines, second);
  auto split = [](const std::string& line) {  // a CSV line's cells, the empty last one included
    std::vector<std::string> cells(1);
    for (char ch : line) {
      if (ch == ',') cells.emplace_back();
      else cells.back().push_back(ch);
    }
    return cells;
  };
  auto field = [&](const std::string& row, const std::string& head, const std::string& name) {
    const auto names = split(head), cells = split(row);
    const auto k = static_cast<std::size_t>(std::find(names.begin(), names.end(), name) - names.begin());
    return k < cells.size() ? cells[k] : std::string("(no column)");
  };
  EXPECT_EQ(field(first, header, "wrist_px_left"), "2");
  EXPECT_EQ(field(second, header, "wrist_px_left"), "");
  EXPECT_EQ(field(second, header, "wrist_px_right"), "9");
}

}  // namespace
}  // namespace spidar::session
