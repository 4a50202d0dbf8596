// spidar-mr render-test: renders the cube scene from the rig camera headless, films synthetic
// "real" hands, and writes the composited frames (PNG) and a short clip (video).
#include <iostream>
#include <memory>

#include "cli_support.hpp"
#include "commands.hpp"
#include "spidar/session/render_test.hpp"

namespace spidar::app {

Action add_render_test(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "render-test",
      "Headless render of a scene from the rig camera with synthetic hands composited in; writes "
      "PNG frames and a short video");
  auto a = std::make_shared<session::RenderTestParams>();
  cmd->add_option("--out", a->out, "output folder")->required();
  cmd->add_option("--scene", a->scene, "MJCF scene")->capture_default_str();
  cmd->add_option("--camera", a->camera, "camera file")->capture_default_str();
  cmd->add_option("--device", a->device, "device config (strings in the overlay)")
      ->capture_default_str();
  cmd->add_option("--mode", a->mode, "compositor mode of the video: depth or paper")
      ->capture_default_str();
  cmd->add_option("--frames", a->frames, "video frames (0 = PNGs only)")->capture_default_str();
  cmd->add_option("--fps", a->fps, "video frame rate")->capture_default_str();
  cmd->add_option("--registration-error-mm", a->registration_error_mm,
                  "offset of the model hands from the true ones along x [mm]")
      ->capture_default_str();
  cmd->add_option("--motion-blur", a->motion_blur, "sub-frames of the synthetic camera (1 = off)")
      ->capture_default_str();
  return [a] {
    require_range(a->frames, 0, 10000, "--frames");
    require_range(a->fps, 1, 240, "--fps", "Hz");
    require_range(a->registration_error_mm, -100, 100, "--registration-error-mm", "mm");
    check_output_dir(a->out, "--out");
    const session::RenderTestResult r = session::run_render_test(*a);
    std::cout << "render-test: GL " << r.gl_renderer << "\n"
              << "  wrote " << a->out << "/{virtual,camera,matte,composite_depth,composite_paper,"
              << "composite_overlay}.png\n";
    if (!r.video_path.empty())
      std::cout << "  video " << r.video_path << " (" << r.video_format << ", " << r.video_frames
                << " frames, " << r.mode << " mode)\n";
    std::cout << "  mean per frame: synthetic camera " << r.ms_film << " ms, render + read " << r.ms_render
              << " ms, chroma key + composite " << r.ms_composite << " ms\n";
    return 0;
  };
}

}  // namespace spidar::app
