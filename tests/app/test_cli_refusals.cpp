// Command-line arguments that are refused before anything runs or is written: empty values,
// output paths that would overwrite the wrong thing or leave debris, repeated fingers, ranges
// with excluded ends, options of the other device backend. Each refusal exits with code 2 and
// names the option. None of these runs the real-time threads (no `realtime` lock).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "run_cli.hpp"
#include "temp_path.hpp"

namespace {

namespace fs = std::filesystem;
using spidar::test::Run;
Run run(const std::string& args) { return spidar::test::run_cli(args); }

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void expect_refused(const std::string& args, const std::string& says) {
  const Run r = run(args);
  EXPECT_EQ(r.code, 2) << args << "\n" << r.out << r.err;
  EXPECT_NE(r.err.find(says), std::string::npos) << args << "\nexpected: " << says << "\ngot: " << r.err;
}

TEST(CliRefusals, AnEmptyValueIsRefusedNamingItsOption) {
  // CLI11 would make '' a 0 or the default without a word.
  expect_refused("demo --seconds ''", "--seconds: expected a value, got an empty one");
  expect_refused("demo --out '' --seconds 1", "--out: expected a value, got an empty one");
  expect_refused("device-test --rate ''", "--rate: expected a value, got an empty one");
  expect_refused("check-config ''", ": expected a value, got an empty one");
}

TEST(CliRefusals, OutputFoldersAreCheckedBeforeAnythingAndARefusedRunLeavesNothing) {
  const fs::path tmp = spidar::test::temp_dir("spidar_cli_refusals_out");
  expect_refused("demo --out / --seconds 1", "--out /: is the filesystem's root");
  expect_refused("render-test --out /", "--out /: is the filesystem's root");
  // A file in the way of the folder, or of one of its parents.
  { std::ofstream(tmp / "a_file") << "x"; }
  expect_refused("demo --out " + (tmp / "a_file").string(), "exists and is not a folder");
  expect_refused("demo --out " + (tmp / "a_file" / "sub").string(), "cannot be made: " + (tmp / "a_file").string() + " is not a folder");
  expect_refused("replay " + tmp.string() + " --out " + (tmp / "a_file").string(), "exists and is not a folder");
  // Something other than a file where an output file goes: refused before the run writes the others.
  fs::create_directories(tmp / "used" / "report.json");
  expect_refused("demo --out " + (tmp / "used").string(),
                 (tmp / "used" / "report.json").string() + " is not a file, where an output file may go");
  expect_refused("replay " + tmp.string() + " --out " + (tmp / "used").string(), "report.json is not a file");
  // A bad input: refused, and the output folder it named was not made.
  const fs::path fresh = tmp / "fresh";
  expect_refused("demo --out " + fresh.string() + " --scene /nonexistent/scene.xml", "/nonexistent/scene.xml");
  EXPECT_FALSE(fs::exists(fresh)) << "a refused demo left its output folder behind";
  expect_refused("demo --out " + fresh.string() + " --user-hand /nonexistent/hands.yaml", "/nonexistent/hands.yaml");
  EXPECT_FALSE(fs::exists(fresh));
}

TEST(CliRefusals, CalibrateCameraReplacesOnlyACameraFile) {
  const fs::path tmp = spidar::test::temp_dir("spidar_cli_refusals_camera");
  const fs::path markers = tmp / "markers.yaml";
  { std::ofstream(markers) << "markers:\n  - {world: [0, 0, 0], pixel: [1, 2]}\n"; }
  const std::string markers_text = read_text(markers);
  expect_refused("calibrate-camera --markers " + markers.string() + " --out " + markers.string(),
                 "--out " + markers.string() + ": is the --markers input");
  EXPECT_EQ(read_text(markers), markers_text);
  // A device config is not a camera file: untouched, and no .bak appears.
  const fs::path device = tmp / "spidar8.yaml";
  fs::copy_file("configs/spidar8.yaml", device, fs::copy_options::overwrite_existing);
  const std::string device_text = read_text(device);
  expect_refused("calibrate-camera --markers " + markers.string() + " --out " + device.string(),
                 "--out " + device.string() + ": exists and is not a camera file");
  EXPECT_EQ(read_text(device), device_text);
  EXPECT_FALSE(fs::exists(device.string() + ".bak"));
  expect_refused("calibrate-camera --markers " + markers.string() + " --out " + (tmp / "cam.yaml").string() + "/",
                 "ends with '/'; expected a camera file, not a folder");
  EXPECT_FALSE(fs::exists(tmp / "cam.yaml"));
  expect_refused("calibrate-camera --markers " + markers.string() + " --square 0.03 --out " + (tmp / "c.yaml").string(),
                 "--square: applies with --images");
  expect_refused("calibrate-camera --images " + tmp.string() + " --square 1e-310 --out " + (tmp / "c.yaml").string(),
                 "--square: square 1e-310: expected a side from 0.0001 to 1 m");
  expect_refused("calibrate-camera --markers " + markers.string() + " --out " + tmp.string(),
                 "exists and is not a file; expected a camera file");
}

TEST(CliRefusals, FlagsThatContradictEachOtherAreRefused) {
  // CLI11 would take whichever came last, without a word. The message names both, in either order.
  for (const std::string args : {"demo --idle-spin --no-idle-spin --seconds 1", "demo --no-idle-spin --idle-spin --seconds 1"})
    expect_refused(args, "--idle-spin excludes --no-idle-spin");
  for (const std::string args : {"demo --bending-wrists --in-line-forearms --seconds 1",
                                 "demo --in-line-forearms --bending-wrists --seconds 1"})
    expect_refused(args, "--bending-wrists excludes --in-line-forearms");
  for (const std::string args : {"demo --ring-on-side --ring-on-back --seconds 1", "demo --ring-on-back --ring-on-side --seconds 1"})
    expect_refused(args, "--ring-on-side excludes --ring-on-back");
  // Each alone still works as before (parsed; the demo itself is not run here).
  expect_refused("demo --in-line-forearms --seconds -1", "--seconds");
  expect_refused("demo --bending-wrists --seconds -1", "--seconds");
  expect_refused("demo --ring-on-back --seconds -1", "--seconds");
  // The fit's margin is an angle within the joints' ranges.
  expect_refused("demo --fit-margin 0.5 --seconds 1", "--fit-margin");
  expect_refused("demo --fit-margin nan --seconds 1", "--fit-margin");
}

TEST(CliRefusals, ASubnormalCoordinateOrForceIsRefused) {
  expect_refused("tension --finger 0 --position 1e-310 0 0 --force 0 0 1",
                 "--position: expected numbers of ordinary size, got 1e-310 (a subnormal number");
  expect_refused("tension --finger 0 --position 0 0 0 --force 0 -4.9e-324 1", "--force: expected numbers of ordinary size");
  // 0 itself, and small ordinary numbers, are fine.
  EXPECT_EQ(run("tension --finger 0 --position 0 1e-300 0 --force 0 0 1").code, 0);
}

TEST(CliRefusals, FingerListsAndRangesSayWhatIsExpected) {
  expect_refused("calibrate-strings --fingers 0,0", "--fingers 0,0: finger 0 (left_thumb) is named twice");
  expect_refused("calibrate-strings --fingers 0,,1", "--fingers 0,,1: expected comma-separated finger names or "
                                                     "indices, got an empty item at character 3");
  expect_refused("calibrate-strings --fingers 0,thumb", "--fingers thumb: unknown finger");
  expect_refused("calibrate-strings --fingers '0, 0'", "--fingers 0, 0: finger 0 (left_thumb) is named twice");
  expect_refused("calibrate-strings --tolerance 0", "--tolerance: expected more than 0 and at most 20 mm, got 0");
  expect_refused("calibrate-strings --timeout 0", "--timeout: expected more than 0 and at most 600 s, got 0");
  expect_refused("calibrate-strings --jig 3 --jig-spacing 0.3", "--jig-spacing: expected 0.005 to 0.2 m, got 0.3");
  expect_refused("calibrate-strings --jig-spacing 0.05", "--jig-spacing: applies to a jig (--jig 2 to 5), not to the pole calibration");
  expect_refused("run --config configs/lab-example.yaml --headless --record-frames png", "--record-frames: applies with --record DIR");
  expect_refused("device-test --seconds 1e-310", "--seconds: expected more than 0 and at most 3600 s, got 1e-310 (too small");
  expect_refused("demo --seconds 1e-320", "--seconds: expected 0 to 600 s, got 9.99989e-321 (too small to be a value");
}

TEST(CliRefusals, AnOptionOfTheOtherBackendIsRefused) {
  expect_refused("device-test --backend sim --port /dev/null", "--port: applies to --backend serial, not to --backend sim");
  expect_refused("device-test --read-timeout 0.5", "--read-timeout: applies to --backend serial");
  expect_refused("device-test --backend serial --port /dev/null --seed 3", "--seed: applies to --backend sim");
  expect_refused("device-test --backend serial --port /dev/null --read-timeout nan",
                 "--read-timeout: expected 0.001 to 1 s, got 'nan'");
  expect_refused("device-test --backend serial --port /dev/null --read-timeout 5", "--read-timeout: expected 0.001 to 1 s, got '5'");
  expect_refused("calibrate-strings --backend sim --baud 9600", "--baud: applies to --backend serial");
}

TEST(CliRefusals, AnOptionOfTheMixedRealityDemoIsRefusedInTheOtherScenarios) {
  expect_refused("demo --scenario haptic --camera configs/camera.yaml", "--camera: applies to --scenario rubiks, not to --scenario haptic");
  expect_refused("demo --scenario strings --no-video", "--no-video: applies to --scenario rubiks, not to --scenario strings");
  expect_refused("demo --scenario strings --scene scenes/blocks.xml", "--scene: applies to --scenario rubiks or haptic");
  expect_refused("demo --scenario haptic --user-hand configs/users/large.yaml", "--user-hand: applies to --scenario rubiks");
}

TEST(CliRefusals, RunRecordsOnlyIntoANewOrEmptyFolderAndSaysSoBeforeStarting) {
  const fs::path tmp = spidar::test::temp_dir("spidar_cli_refusals_record");
  fs::create_directories(tmp / "mine");
  { std::ofstream(tmp / "mine" / "device.csv") << "my own data\n"; }
  expect_refused("run --config configs/lab-example.yaml --headless --seconds 1 --record " + (tmp / "mine").string(),
                 "--record " + (tmp / "mine").string() + ": is not empty (it holds device.csv)");
  EXPECT_EQ(read_text(tmp / "mine" / "device.csv"), "my own data\n");
  expect_refused("run --config configs/lab-example.yaml --headless --seconds 1 --record /", "--record /: is the filesystem's root");
}

TEST(CliRefusals, RunChecksItsScreenshotPathBeforeTheSession) {
  const fs::path tmp = spidar::test::temp_dir("spidar_cli_refusals_run");
  { std::ofstream(tmp / "a_file") << "x"; }
  expect_refused("run --config configs/lab-example.yaml --headless --screenshot " + (tmp / "shot.png").string(),
                 "--screenshot: saves the window's pixels; there is no window with --headless");
  expect_refused("run --config configs/lab-example.yaml --screenshot " + (tmp / "a_file" / "shot.png").string(),
                 "--screenshot " + (tmp / "a_file" / "shot.png").string() + ": cannot be made");
}

}  // namespace
