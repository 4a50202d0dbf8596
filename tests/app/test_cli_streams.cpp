// stdout carries only a command's result; logs and warnings go to stderr.
#include <gtest/gtest.h>

#include <cstdlib>
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

}  // namespace
}  // namespace spidar::test
