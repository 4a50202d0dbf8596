// spidar-mr calibrate-camera: intrinsics from a folder of chessboard images, extrinsics from a
// markers file (PnP or the paper's three markers), written as a camera file.
#include <filesystem>
#include <iostream>
#include <memory>

#include "spidar/session/json_text.hpp"
#include "cli_support.hpp"
#include "spidar/core/file_write.hpp"
#include "commands.hpp"
#include "spidar/vision/camera_config.hpp"
#include "spidar/vision/chessboard.hpp"
#include "spidar/vision/lens_undistortion.hpp"
#include "spidar/core/file_read.hpp"
#include "spidar/vision/markers.hpp"

namespace spidar::app {

namespace {

struct CalibrateCameraArgs {
  std::string images;
  std::string pattern = "9x6";
  double square = 0.025;
  std::string markers;
  std::string base;
  std::string out = "configs/camera.yaml";
  bool k3 = false;
};

/// Refuses a calibration whose lens folds the image (the camera-file loader, and every session,
/// would refuse it) before it is written: the images' views do not fit one real camera.
void require_usable_lens(const vision::Camera& camera, const std::string& out) {
  if (auto st = vision::LensUndistortion::check(camera.intrinsics()); !st)
    throw UsageError("--images: the calibration found is not a usable camera (" + st.error().message +
                     "); nothing written to " + core::printable_for_message(out) +
                     ": take the chessboard in more and better-spread views, or fix k3 (no --k3)");
}

/// Refuses an --out that would overwrite something other than a camera file (its own --markers,
/// a device config, a folder): calibrate-camera replaces only a camera file, keeping it as .bak.
void check_camera_out(const CalibrateCameraArgs& a) {
  check_output_file(a.out, "--out", "a camera file");
  namespace fs = std::filesystem;
  std::error_code ec;
  const std::string shown = "--out " + core::printable_for_message(a.out);
  for (const auto& [input, option] : {std::pair{&a.markers, "--markers"}, std::pair{&a.images, "--images"}})
    if (!input->empty() && fs::equivalent(a.out, *input, ec))
      throw UsageError(shown + ": is the " + option + " input; expected another path for the camera file");
  if (!fs::exists(a.out, ec)) return;
  try {
    (void)vision::load_camera_file(a.out);
  } catch (const SpidarError& e) {
    throw UsageError(shown + ": exists and is not a camera file (" + e.what() +
                     "); calibrate-camera replaces only a camera file: choose another path");
  }
}

/// Extrinsics alone (no --images): the markers against the intrinsics of `base` (the existing
/// camera file; the default rig camera if there is none), written with the new pose.
int extrinsics_only(const CalibrateCameraArgs& a, const std::string& base) {
  if (a.markers.empty())
    throw UsageError("--images or --markers: expected chessboard images, markers, or both");
  const vision::CameraFile kept = base.empty() ? vision::CameraFile{vision::default_rig_camera(), {}, ""}
                                               : vision::load_camera_file(base);
  const auto set = vision::load_markers(a.markers);
  auto r = vision::calibrate_extrinsics(kept.camera.intrinsics(), set);
  if (!r) throw UsageError("--markers " + r.error().message);
  vision::CalibrationNotes notes = kept.calibration;
  notes.method = (notes.intrinsics_rms_px ? "chessboard + " : "") + r->method;
  notes.extrinsics_rms_px = r->rms_px;
  notes.extrinsics_rms_m = r->rms_m;
  const vision::Camera camera(kept.camera.intrinsics(), r->X_CW);
  const std::string backup = core::keep_previous_version(a.out);
  if (auto s = vision::save_camera_file(a.out, camera, notes); !s.ok()) throw UsageError("--out " + s.error().message);
  nlohmann::json extr = {{"method", r->method}, {"markers", set.markers.size()}};
  if (r->rms_px) extr["rms_px"] = *r->rms_px;
  if (r->max_px) extr["max_px"] = *r->max_px;
  if (r->rms_m) extr["rms_m"] = *r->rms_m;
  const nlohmann::json j = {{"out", a.out},
                            {"backup", backup},
                            {"intrinsics", {{"kept_from", base.empty() ? "default rig camera" : base}}},
                            {"extrinsics", extr},
                            {"camera_position", to_json(camera.X_WC().p)}};
  require_finite_json(j, "calibrate-camera output");
  std::cout << session::json_text(j) << "\n";
  return 0;
}

}  // namespace

Action add_calibrate_camera(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "calibrate-camera",
      "Camera intrinsics from chessboard images, extrinsics from markers; writes a camera file");
  auto a = std::make_shared<CalibrateCameraArgs>();
  cmd->add_option("--images", a->images,
                  "folder of chessboard images (intrinsics); without it the intrinsics are kept "
                  "from --base and only --markers is solved");
  CLI::Option* pattern_opt = cmd->add_option("--pattern", a->pattern, "inner corners COLSxROWS")->capture_default_str();
  CLI::Option* square_opt = cmd->add_option("--square", a->square, "side of one square [m]")->capture_default_str();
  cmd->add_option("--markers", a->markers,
                  "markers file (YAML): world + pixel (PnP, >= 4) or world + camera (3, the "
                  "paper's method)");
  cmd->add_option("--base", a->base,
                  "camera file whose extrinsics are kept when --markers is not given (default: "
                  "--out if it exists, else the default rig camera)");
  cmd->add_option("--out", a->out, "camera file to write")->capture_default_str();
  cmd->add_flag("--k3", a->k3, "also estimate the k3 distortion coefficient (default: k3 = 0)");
  return [a, pattern_opt, square_opt] {
    if (a->images.empty())
      for (const CLI::Option* o : {pattern_opt, square_opt})
        refuse_given(o, "with --images (the chessboard pictures), not to --markers alone");
    check_camera_out(*a);
    // The camera file whose parts are kept (intrinsics without --images, pose without --markers).
    std::string base = a->base;
    if (base.empty() && std::filesystem::exists(a->out)) base = a->out;
    if (a->images.empty()) return extrinsics_only(*a, base);
    auto pattern = vision::parse_pattern(a->pattern, a->square);
    if (!pattern)
      throw UsageError((pattern.error().message.rfind("square", 0) == 0 ? "--square: " : "--pattern: ") +
                       pattern.error().message);
    vision::IntrinsicsOptions options;
    options.fix_k3 = !a->k3;
    auto folder = vision::calibrate_chessboard_folder(a->images, *pattern, options);
    if (!folder) throw UsageError("--images " + folder.error().message);
    const auto& cal = folder->calibration;

    vision::CalibrationNotes notes;
    notes.intrinsics_rms_px = cal.rms_px;
    nlohmann::json extr;
    Pose X_CW;
    if (!a->markers.empty()) {
      const auto set = vision::load_markers(a->markers);
      auto r = vision::calibrate_extrinsics(cal.intrinsics, set);
      if (!r) throw UsageError("--markers " + r.error().message);
      X_CW = r->X_CW;
      notes.method = "chessboard + " + r->method;
      notes.extrinsics_rms_px = r->rms_px;
      notes.extrinsics_rms_m = r->rms_m;
      extr = {{"method", r->method}, {"markers", set.markers.size()}};
      if (r->rms_px) extr["rms_px"] = *r->rms_px;
      if (r->max_px) extr["max_px"] = *r->max_px;
      if (r->rms_m) extr["rms_m"] = *r->rms_m;
    } else {
      if (base.empty()) {
        X_CW = vision::default_rig_camera().X_CW();
        extr = {{"method", "default rig pose (no --markers)"}};
      } else {
        X_CW = vision::load_camera_file(base).camera.X_CW();
        extr = {{"method", "kept from " + base + " (no --markers)"}};
      }
      notes.method = "chessboard";
    }
    const vision::Camera camera(cal.intrinsics, X_CW);
    require_usable_lens(camera, a->out);
    const std::string backup = core::keep_previous_version(a->out);  // the previous calibration stays
    if (auto s = vision::save_camera_file(a->out, camera, notes); !s.ok()) {
      throw UsageError("--out " + s.error().message);
    }
    const auto& in = cal.intrinsics;
    const auto& d = in.distortion;
    const Vec3 p_WC = camera.X_WC().p;
    nlohmann::json j = {
        {"out", a->out},
        {"backup", backup},
        {"images", folder->used.size() + folder->rejected.size()},
        {"boards_found", folder->used.size()},
        {"rejected", folder->rejected},
        {"intrinsics",
         {{"fx", in.fx}, {"fy", in.fy}, {"cx", in.cx}, {"cy", in.cy},
          {"distortion", {d.k1, d.k2, d.p1, d.p2, d.k3}},
          {"image_size", {in.width, in.height}},
          {"rms_px", cal.rms_px}}},
        {"extrinsics", extr},
        {"camera_position", to_json(p_WC)}};
    require_finite_json(j, "calibrate-camera output");
    std::cout << session::json_text(j) << "\n";
    return 0;
  };
}

}  // namespace spidar::app
