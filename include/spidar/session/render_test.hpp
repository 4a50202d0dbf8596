#pragma once
/// The render test (`spidar-mr render-test`): renders a scene headless from the rig camera, films
/// synthetic "real" hands (the simulated user, slightly smaller than the model's default hand)
/// reaching over it, composites them in, and writes into `out` the first frame's PNGs
/// (virtual, camera, matte, composite_depth, composite_paper, composite_overlay) and a video.
#include <string>

namespace spidar::session {

struct RenderTestParams {
  std::string out;                              ///< output folder (created)
  std::string scene = "scenes/rubiks_cube.xml";  ///< MJCF (resolve_data_path)
  std::string camera = "configs/camera.yaml";
  std::string device = "configs/spidar8.yaml";  ///< its strings are drawn in the overlay
  std::string mode = "depth";                   ///< the video's compositor: depth | paper
  int frames = 24;                              ///< video frames (0: PNGs only)
  double fps = 24;                              ///< video rate [Hz]
  double registration_error_mm = 3.0;           ///< model hands offset along x from the true ones [mm]
  int motion_blur = 1;                          ///< synthetic camera sub-frames (1: off)
};

struct RenderTestResult {
  std::string gl_renderer;
  std::string mode;  ///< the video's compositor mode, as parsed
  std::string video_path, video_format;  ///< empty without a video
  int video_frames = 0;
  double ms_film = 0, ms_render = 0, ms_composite = 0;  ///< mean per frame [ms]
};

/// Runs the render test. Throws SpidarError naming the option for bad input (exit code 2).
RenderTestResult run_render_test(const RenderTestParams& p);

}  // namespace spidar::session
