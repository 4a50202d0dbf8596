#include "spidar/session/live_config.hpp"

#include <filesystem>
#include <sstream>

#include "spidar/session/data_path.hpp"
#include "spidar/core/config.hpp"
#include "spidar/hand/hand_config.hpp"

namespace spidar::session {
namespace {

namespace fs = std::filesystem;
using core::ConfigNode;

/// A file named at `node`: relative to the config's folder, else as given, else the data folder.
std::string existing_file(const ConfigNode& node, const fs::path& base) {
  const std::string given = node.as_string();
  if (given.empty()) node.fail("expected a file path, got an empty string");
  const fs::path p(given);
  if (p.is_absolute()) {
    if (!fs::is_regular_file(p)) node.fail("no such file '" + given + "'");
    return p.string();
  }
  for (const fs::path& c : {base / p, p, fs::path(resolve_data_path(given))}) {
    std::error_code ec;
    if (fs::is_regular_file(c, ec)) return fs::absolute(c).lexically_normal().string();
  }
  node.fail("no such file '" + given + "' (looked in " + base.string() +
            ", the working directory and the data directory)");
}

std::string one_of(const ConfigNode& node, std::initializer_list<std::string_view> allowed) {
  const std::string v = node.as_string();
  std::string list;
  for (std::string_view a : allowed) {
    if (v == a) return v;
    list += (list.empty() ? "" : " | ") + std::string(a);
  }
  node.fail("expected " + list + ", got '" + v + "'");
}

int int_in(const ConfigNode& node, std::int64_t lo, std::int64_t hi, std::string_view unit) {
  const std::int64_t v = node.as_int();
  if (v < lo || v > hi) {
    std::ostringstream os;
    os << "expected " << lo << " to " << hi << ' ' << unit << ", got " << v;
    node.fail(os.str());
  }
  return static_cast<int>(v);
}

}  // namespace

LiveConfig load_live_config(const std::string& path, bool check_hardware) {
  const ConfigNode root = ConfigNode::LoadFile(path);
  if (!root.is_map()) root.fail("expected a map with device, camera, scene, hands, compositor");
  root.expect_keys({"device", "camera", "vision", "registration", "scene", "hands", "compositor", "window"});
  const fs::path base = fs::path(path).parent_path().empty() ? fs::path(".") : fs::path(path).parent_path();
  LiveConfig c;
  c.source = path;

  const ConfigNode dev = root["device"];
  dev.expect_keys({"backend", "config", "port", "baud", "rate_hz", "seed"});
  c.backend = one_of(dev["backend"], {"sim", "serial"});
  c.device_config = existing_file(dev["config"], base);
  if (auto n = dev.find("rate_hz")) c.rate_hz = core::require_in_range(*n, n->as_double(), 100, 20000, "Hz");
  if (auto n = dev.find("seed")) c.seed = static_cast<std::uint64_t>(int_in(*n, 0, 1 << 30, ""));
  if (auto n = dev.find("baud")) c.baud = int_in(*n, 1200, 20000000, "baud");
  if (c.backend == "serial") {
    const auto port = dev.find("port");
    if (!port) dev.fail("backend serial needs port: (e.g. /dev/ttyACM0)");
    c.port = port->as_string();
    std::error_code ec;
    if (check_hardware && !fs::exists(c.port, ec))
      port->fail("no such serial port '" + c.port + "' (is the device plugged in? ls /dev/ttyACM* /dev/ttyUSB*)");
  }

  const ConfigNode cam = root["camera"];
  cam.expect_keys({"source", "device", "file", "calibration", "width", "height", "fps"});
  c.camera_source = one_of(cam["source"], {"synthetic", "device", "file"});
  c.camera_calibration = existing_file(cam["calibration"], base);
  if (auto n = cam.find("width")) c.width = int_in(*n, 64, 3840, "px");
  if (auto n = cam.find("height")) c.height = int_in(*n, 48, 2160, "px");
  if (auto n = cam.find("fps")) c.fps = core::require_in_range(*n, n->as_double(), 1, 240, "Hz");
  if (c.camera_source == "device") {
    const auto d = cam.find("device");
    if (!d) cam.fail("source device needs device: (an index such as 0, or a path such as /dev/video0)");
    c.camera_device = d->as_string();
    const bool index = !c.camera_device.empty() &&
                       c.camera_device.find_first_not_of("0123456789") == std::string::npos;
    const std::string dev_path = index ? "/dev/video" + c.camera_device : c.camera_device;
    std::error_code ec;
    if (check_hardware && !fs::exists(dev_path, ec))
      d->fail("no such camera '" + dev_path + "' (is it plugged in? v4l2-ctl --list-devices)");
  } else if (c.camera_source == "file") {
    const auto f = cam.find("file");
    if (!f) cam.fail("source file needs file: (a video file or an image pattern such as frames/%04d.png)");
    const std::string given = f->as_string();
    if (given.find('%') != std::string::npos) {
      const fs::path p = fs::path(given).is_absolute() ? fs::path(given) : base / given;
      c.camera_file = p.string();  // an image sequence: the capture reports a missing first image
    } else {
      c.camera_file = existing_file(*f, base);
    }
  }

  c.vision_config = existing_file(root["vision"], base);
  c.registration_config = existing_file(root["registration"], base);
  c.scene = existing_file(root["scene"], base);

  const ConfigNode hands = root["hands"];
  hands.expect_keys({"file", "model", "user", "control"});
  c.hands_file = existing_file(hands["file"], base);
  // A profile named here must exist (only an absent `user` falls back to the file's first).
  const hand::HandProfiles profiles = hand::load_hand_profiles(c.hands_file);
  auto profile = [&](const ConfigNode& n) {
    std::string name = n.as_string();
    if (profiles.find(name) == nullptr) {
      std::string known;
      for (const auto& p : profiles.profiles) known += (known.empty() ? "" : ", ") + p.name;
      n.fail("no hand profile '" + name + "' in " + c.hands_file + "; expected one of: " + known);
    }
    return name;
  };
  if (auto n = hands.find("model")) c.model_profile = profile(*n);
  if (auto n = hands.find("user")) c.user_profile = profile(*n);
  if (auto n = hands.find("control")) c.user_mode = one_of(*n, {"scripted", "interactive"});
  if (c.camera_source == "synthetic" && c.backend != "sim")
    root["camera"]["source"].fail(
        "the synthetic camera films the simulated user: it needs device.backend: sim");
  if (c.user_mode == "interactive" && c.backend != "sim")
    hands["control"].fail("interactive hands drive the simulated user: they need device.backend: sim");

  if (auto comp = root.find("compositor")) {
    comp->expect_keys({"mode", "silhouette"});
    if (auto n = comp->find("mode")) c.compositor = one_of(*n, {"paper", "depth"});
    if (auto n = comp->find("silhouette")) c.silhouette = n->as_bool();
  }
  if (auto win = root.find("window")) {
    win->expect_keys({"width", "height"});
    if (auto n = win->find("width")) c.window_width = int_in(*n, 320, 7680, "px");
    if (auto n = win->find("height")) c.window_height = int_in(*n, 240, 4320, "px");
  }
  return c;
}

std::string live_config_yaml(const LiveConfig& c) {
  std::ostringstream os;
  os << "# spidar-mr live session config as used (paths resolved; see configs/lab-example.yaml)\n"
     << "# from " << c.source << "\n"
     << "device:\n  backend: " << c.backend << "\n  config: \"" << c.device_config << "\"\n";
  if (!c.port.empty()) os << "  port: \"" << c.port << "\"\n";
  os << "  baud: " << c.baud << "\n  rate_hz: " << c.rate_hz << "\n  seed: " << c.seed << "\n"
     << "camera:\n  source: " << c.camera_source << "\n";
  if (!c.camera_device.empty()) os << "  device: \"" << c.camera_device << "\"\n";
  if (!c.camera_file.empty()) os << "  file: \"" << c.camera_file << "\"\n";
  os << "  calibration: \"" << c.camera_calibration << "\"\n  width: " << c.width
     << "\n  height: " << c.height << "\n  fps: " << c.fps << "\n"
     << "vision: \"" << c.vision_config << "\"\nregistration: \"" << c.registration_config
     << "\"\nscene: \"" << c.scene << "\"\n"
     << "hands:\n  file: \"" << c.hands_file << "\"\n  model: " << c.model_profile
     << "\n  user: " << c.user_profile << "\n  control: " << c.user_mode << "\n"
     << "compositor:\n  mode: " << c.compositor << "\n  silhouette: " << (c.silhouette ? "true" : "false")
     << "\nwindow:\n  width: " << c.window_width << "\n  height: " << c.window_height << "\n";
  return os.str();
}

}  // namespace spidar::session
