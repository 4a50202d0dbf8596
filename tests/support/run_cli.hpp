#pragma once
// Runs the spidar-mr binary (SPIDAR_MR, set by CMake) as a user would: stdout, stderr, exit code.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <string>

namespace spidar::test {

struct Run {
  int code;
  std::string out;  // stdout
  std::string err;  // stderr
};

/// `prefix` goes before the binary (e.g. "xvfb-run -a "). Stderr goes through one file per
/// process: ctest runs the tests of a binary in parallel processes.
inline Run run_cli(const std::string& args, const std::string& prefix = "") {
  const std::string err_file =
      ::testing::TempDir() + "spidar_cli_stderr_" + std::to_string(getpid()) + ".txt";
  const std::string cmd = prefix + std::string(SPIDAR_MR) + " " + args + " 2>" + err_file;
  Run r{-1, "", ""};
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  std::array<char, 4096> buf{};
  while (fgets(buf.data(), buf.size(), p)) r.out += buf.data();
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (FILE* e = fopen(err_file.c_str(), "r")) {
    while (fgets(buf.data(), buf.size(), e)) r.err += buf.data();
    fclose(e);
  }
  std::remove(err_file.c_str());
  return r;
}

}  // namespace spidar::test
