// stdout carries only a command's result; logs and warnings go to stderr.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <nlohmann/json.hpp>

#include "run_cli.hpp"

namespace spidar::test {
namespace {

// Without real-time permission the servo loop warns (SCHED_FIFO not permitted): the warning must
// not land in stdout ahead of the JSON. setpriv drops CAP_SYS_NICE, which is all root has for it.
TEST(CliStreams, SchedulingWarningGoesToStderrAndStdoutStaysJson) {
  if (std::system("command -v setpriv >/dev/null 2>&1") != 0) GTEST_SKIP() << "setpriv missing";
  const spidar::test::Run r = run_cli("device-test --backend sim --seconds 0.3",
                        "setpriv --bounding-set=-sys_nice --inh-caps=-sys_nice ");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(nlohmann::json::accept(r.out)) << "stdout: " << r.out.substr(0, 200);
  if (r.err.find("SCHED_FIFO") == std::string::npos) {
    GTEST_SKIP() << "real-time priority was granted anyway (no warning to route)";
  }
  EXPECT_NE(r.err.find("rtprio"), std::string::npos) << "the warning says what to do: " << r.err;
}


// Without real-time permission the demo still runs, says once that its frame thread runs without
// SCHED_FIFO (and what that costs), and its report says so.
TEST(CliStreams, WithoutRealTimePermissionTheDemoSaysSoOnceAndReportsIt) {
  if (std::system("command -v setpriv >/dev/null 2>&1") != 0) GTEST_SKIP() << "setpriv missing";
  const std::string dir = ::testing::TempDir() + "spidar_cli_no_rt_" + std::to_string(getpid());
  std::filesystem::remove_all(dir);
  const spidar::test::Run r = run_cli("demo --seconds 1 --no-video --width 320 --height 240 --out " + dir,
                                      "setpriv --bounding-set=-sys_nice --inh-caps=-sys_nice ");
  ASSERT_EQ(r.code, 0) << r.err;
  if (r.err.find("SCHED_FIFO") == std::string::npos) {
    std::filesystem::remove_all(dir);
    GTEST_SKIP() << "real-time priority was granted anyway";
  }
  const std::string said = "session: the frame thread runs at nice";
  const auto first = r.err.find(said);
  ASSERT_NE(first, std::string::npos) << r.err;
  EXPECT_EQ(r.err.find(said, first + 1), std::string::npos) << "said more than once: " << r.err;
  EXPECT_NE(r.err.find("expect more latency and dropped frames"), std::string::npos) << r.err;
  std::ifstream report(dir + "/report.json");
  ASSERT_TRUE(report.good()) << "no report.json in " << dir;
  const auto j = nlohmann::json::parse(report);
  EXPECT_EQ(j.at("pipeline").at("frame_thread_fifo"), false);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace spidar::test
