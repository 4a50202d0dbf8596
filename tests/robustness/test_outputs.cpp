// Outputs that never lie: every file is written whole or not at all (a path that cannot be
// written fails the command naming it), and no JSON we write holds a null.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "run_cli.hpp"
#include "temp_path.hpp"

namespace spidar::test {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// demo's CSVs (walkthrough.csv here; haptic_trace.csv goes through the same writer) were written
// with a plain std::ofstream: a path that could not be written was silently skipped, exit 0, and
// "wrote walkthrough.csv" printed. Now: exit 2 naming the file, and no report claiming the run.
TEST(Outputs, ADemoCsvThatCannotBeWrittenFailsTheDemoNamingIt) {
  const fs::path dir = temp_dir("robust_demo_csv");
  fs::create_directories(dir / "walkthrough.csv");  // in the way: a directory
  const spidar::test::Run r = run_cli("demo --scenario strings --seconds 0.3 --out " + dir.string(), "timeout 120 ");
  EXPECT_EQ(r.code, 2) << r.err;
  // Found before the run (check_output_dir), not after it has written the other files.
  EXPECT_NE(r.err.find((dir / "walkthrough.csv").string() + " is not a file, where an output file may go"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir / "report.json"));
  EXPECT_EQ(r.out.find("wrote "), std::string::npos) << r.out;

  // A symbolic link is written through, the whole file at once: a full table behind the link.
  const fs::path ok = temp_dir("robust_demo_csv_link");
  const fs::path target = ok / "kept" / "table.csv";
  fs::create_directories(target.parent_path());
  fs::create_symlink(target, ok / "walkthrough.csv");
  const spidar::test::Run r2 = run_cli("demo --scenario strings --seconds 0.3 --out " + ok.string(), "timeout 120 ");
  ASSERT_EQ(r2.code, 0) << r2.err;
  EXPECT_TRUE(fs::is_symlink(ok / "walkthrough.csv"));
  const std::string csv = slurp(target);
  ASSERT_FALSE(csv.empty());
  EXPECT_EQ(csv.rfind("t,finger,", 0), 0u);
  EXPECT_EQ(csv.back(), '\n') << "cut mid-row";
}

// An output folder that is a file, or under one, was "internal error: filesystem error" with
// exit 1 (the servo-fault code): now exit 2 naming the path, for every command that writes one.
TEST(Outputs, AnOutputFolderThatIsAFileIsNamedWithExit2) {
  const fs::path dir = temp_dir("robust_out_is_file");
  const std::string file = (dir / "a_file").string();
  std::ofstream(file) << "not a folder\n";
  for (const std::string& cmd :
       {"demo --scenario strings --seconds 0.2 --out " + file, "demo --scenario haptic --seconds 0.2 --out " + file,
        "render-test --frames 0 --out " + file,
        "run --config configs/lab-example.yaml --headless --seconds 0.2 --record " + file + "/rec"}) {
    SCOPED_TRACE(cmd);
    const spidar::test::Run r = run_cli(cmd, "timeout 120 ");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find(file), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
  }
  EXPECT_EQ(slurp(file), "not a folder\n");
}

// A recording whose fingertip log is empty (and session.json agrees) replays, but the comparison
// it could not make is named, not written as null nor as a perfect 0.
TEST(Outputs, ReplayOfARecordingWithNoFingertipSamplesWritesNoNull) {
  const fs::path dir = temp_dir("robust_replay_no_tips");
  const fs::path rec = dir / "rec";
  const spidar::test::Run made = run_cli("run --config configs/lab-example.yaml --headless --seconds 1.5 --record " + rec.string(),
                           "timeout 120 ");
  ASSERT_EQ(made.code, 0) << made.err << made.out;
  const std::string tips = slurp(rec / "fingertips.csv");
  std::ofstream(rec / "fingertips.csv", std::ios::binary) << tips.substr(0, tips.find('\n') + 1);
  auto session = nlohmann::json::parse(slurp(rec / "session.json"));
  session["rows"]["fingertips"] = 0;
  std::ofstream(rec / "session.json", std::ios::binary) << session.dump(2) << "\n";

  const spidar::test::Run r = run_cli("replay " + rec.string() + " --no-video --out " + (dir / "replay").string(), "timeout 120 ");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string text = slurp(dir / "replay" / "report.json");
  EXPECT_EQ(text.find("null"), std::string::npos) << text;
  EXPECT_EQ(r.out.find("null"), std::string::npos) << r.out;
  const auto j = nlohmann::json::parse(text);
  const auto& rep = j["reproduction"];
  EXPECT_EQ(rep["fingertip_resample_frames"].get<int>(), 0);
  EXPECT_FALSE(rep.contains("fingertip_resample_max_mm")) << rep;
  ASSERT_TRUE(rep["not_measured"].is_array()) << rep;
  EXPECT_NE(std::find(rep["not_measured"].begin(), rep["not_measured"].end(), "fingertip_resample_max_mm"),
            rep["not_measured"].end())
      << rep;
  EXPECT_EQ(j["recorded"]["fingertip_samples"].get<int>(), 0);
}

}  // namespace
}  // namespace spidar::test
