// Every file a command line names is read through one bounded loader: a device (/dev/zero grows
// without end), a FIFO (blocks until a writer comes) or a directory is refused at once with exit
// 2 naming the path, whichever option names it. The loaders have their own tests (tests/core,
// tests/physics); this checks that every option is wired to them. Each run is under `timeout`,
// so a command that hangs fails the test (exit 124) instead of hanging it.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "run_cli.hpp"
#include "temp_path.hpp"

namespace spidar::test {
namespace {

struct Option {
  std::string name;    ///< for messages
  std::string before;  ///< the command line up to the path
  std::string after;   ///< after it
};

TEST(FileArguments, DevicesFifosAndDirectoriesAreRefusedByEveryOption) {
  const std::string dir = temp_dir("robust_file_args");
  const std::string fifo = dir + "/fifo";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const std::string out = " --out " + dir + "/out";
  const std::vector<Option> options = {
      {"check-config", "check-config ", ""},
      {"position --config", "position --finger 0 --lengths 0.3 0.3 0.3 --config ", ""},
      {"device-test --config", "device-test --seconds 0.2 --config ", ""},
      {"demo --config", "demo --scenario strings --seconds 0.2 --config ", out},
      {"demo --scene", "demo --scenario haptic --seconds 0.2 --scene ", out},
      {"demo --user-hand", "demo --seconds 0.2 --no-video --user-hand ", out},
      {"demo --camera", "demo --seconds 0.2 --no-video --camera ", out},
      {"render-test --scene", "render-test --frames 0 --scene ", out},
      {"render-test --camera", "render-test --frames 0 --camera ", out},
      {"run --config", "run --headless --seconds 0.2 --config ", ""},
  };
  for (const std::string& path : {std::string("/dev/zero"), fifo, dir}) {
    for (const Option& o : options) {
      SCOPED_TRACE(o.name + " " + path);
      const spidar::test::Run r = run_cli(o.before + path + o.after, "timeout 60 ");
      EXPECT_EQ(r.code, 2) << r.err;
      EXPECT_NE(r.err.find(path + ":"), std::string::npos) << r.err;
      EXPECT_NE(r.err.find(path == dir ? ": is a directory" : ": is not a regular file"), std::string::npos)
          << r.err;
    }
  }
}

}  // namespace
}  // namespace spidar::test

namespace spidar::test {
namespace {

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void replace_once(std::string& text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  ASSERT_NE(at, std::string::npos) << "configs/lab-example.yaml changed: '" << from << "' not found";
  text.replace(at, from.size(), to);
}

// A profile that is named must exist: the registration's model (demo --model-hand, hands.model)
// and the simulated user (hands.user) used to fall back silently to another profile.
TEST(FileArguments, NamedHandProfilesMustExist) {
  const spidar::test::Run demo = run_cli("demo --seconds 0.2 --no-video --model-hand nosuch --out " +
                               temp_dir("robust_profile_demo"),
                           "timeout 60 ");
  EXPECT_EQ(demo.code, 2) << demo.err;
  EXPECT_NE(demo.err.find("hands.yaml: no hand profile 'nosuch'"), std::string::npos) << demo.err;

  const std::string dir = temp_dir("robust_profile_run");
  std::string lab = read_text("configs/lab-example.yaml");
  const std::string src = std::filesystem::current_path().string();
  for (const char* file : {"spidar8.yaml", "camera.yaml", "vision.yaml", "registration.yaml", "hands.yaml"})
    replace_once(lab, std::string(": ") + file, std::string(": ") + src + "/configs/" + file);
  replace_once(lab, ": ../scenes/", ": " + src + "/scenes/");
  for (const char* key : {"model: model", "user: user"}) {
    SCOPED_TRACE(key);
    std::string bad = lab;
    const std::string k = std::string(key).substr(0, std::string(key).find(':'));
    replace_once(bad, key, k + ": nosuch");
    const std::string path = dir + "/lab_" + k + ".yaml";
    std::ofstream(path) << bad;
    int line = 1;
    for (std::size_t i = 0; i < bad.find(k + ": nosuch"); ++i) line += bad[i] == '\n';
    const spidar::test::Run r = run_cli("run --headless --seconds 0.5 --config " + path, "timeout 60 ");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find(path + ":" + std::to_string(line) + ": hands." + k + ": no hand profile 'nosuch' in "),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("expected one of: model, user"), std::string::npos) << r.err;
  }
}

}  // namespace
}  // namespace spidar::test
