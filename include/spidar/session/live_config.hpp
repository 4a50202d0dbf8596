#pragma once
/// The live session's configuration (`spidar-mr run --config lab.yaml`): one YAML file that names
/// the device backend, the camera, the calibration files, the scene, the hand sizes and the
/// compositor. configs/lab-example.yaml documents every key. Relative paths are taken relative to
/// the YAML file's folder first, then the working directory, then the installed data directory.
#include <cstdint>
#include <string>

namespace spidar::session {

struct LiveConfig {
  std::string source;  ///< the YAML file it came from

  // device
  std::string backend = "sim";  ///< sim | serial
  std::string device_config;    ///< device layout and calibration (strings::DeviceConfig YAML)
  std::string port;             ///< serial: tty path
  int baud = 2000000;           ///< serial
  double rate_hz = 1000.0;      ///< servo rate [Hz]
  std::uint64_t seed = 1;       ///< sim: noise seed

  // camera
  std::string camera_source = "synthetic";  ///< synthetic | device | file
  std::string camera_device;                ///< device: index ("0") or path ("/dev/video0")
  std::string camera_file;                  ///< file: video file or image-sequence pattern
  std::string camera_calibration;           ///< vision::CameraFile YAML (intrinsics + pose)
  int width = 640, height = 480;            ///< image size [px]
  double fps = 30.0;                        ///< camera rate [Hz]

  std::string vision_config;        ///< chroma key and bracelet (vision::VisionConfig YAML)
  std::string registration_config;  ///< registration parameters YAML
  std::string scene;                ///< MJCF scene

  // hands
  std::string hands_file;              ///< hand profiles YAML
  std::string model_profile = "model"; ///< the registration's hand sizes
  std::string user_profile = "user";   ///< the simulated user's hands (synthetic camera)
  std::string user_mode = "scripted";  ///< scripted | interactive (simulated rig only)

  // compositor
  std::string compositor = "depth";  ///< paper | depth
  bool silhouette = true;            ///< the silhouette term in the registration

  // window
  int window_width = 1280, window_height = 800;
};

/// Loads and validates a live config. Throws core::ConfigError (`file:line: key: expectation`)
/// on a bad value, an unknown key or a file it names that does not exist. With `check_hardware`
/// the serial port and camera device must exist too (off for replaying a recording).
LiveConfig load_live_config(const std::string& path, bool check_hardware = true);

/// The config as YAML text with every path resolved (absolute), as a recording stores it.
std::string live_config_yaml(const LiveConfig& c);

}  // namespace spidar::session
