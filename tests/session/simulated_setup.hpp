#pragma once
// A Session on the simulated rig for the session's tests: the default user and model hands, the
// Rubik's cube scene, 320×240 at 30 fps, a headless GL context.
#include <array>
#include <functional>
#include <memory>

#include "spidar/render/context.hpp"
#include "spidar/session/rig.hpp"
#include "spidar/session/rig_inputs.hpp"
#include "spidar/session/session.hpp"
#include "spidar/strings/device_config.hpp"
#include "spidar/vision/camera_config.hpp"

namespace spidar::session {

/// Everything a session on the simulated rig needs, at 320×240 and 30 fps.
struct SimulatedSetup {
  explicit SimulatedSetup(double seconds, bool warm_up = true,
                          const std::function<void(SessionParams&)>& tweak = {}) {
    auto ctx = render::Context::create_headless();
    if (!ctx) throw SpidarError("OpenGL: " + ctx.error().message);
    context = std::move(ctx).value();
    config = strings::load_device_config("configs/spidar8.yaml");
    user = hand_models("configs/hands.yaml", "user", true);
    models = hand_models("configs/hands.yaml", "model", false);
    camera = scaled_camera(vision::load_camera_file("configs/camera.yaml").camera, 320, 240);
    scene = Scene::load("scenes/rubiks_cube.xml", user).value();
    SimulatedRigParams rp;
    rp.seed = 3;
    rp.fps = 30;
    rig = std::make_unique<SimulatedRig>(config, *scene, camera, user, rp);
    SessionParams sp;
    sp.servo.rate_hz = 1000;
    sp.servo.force_timeout_s = 0.05;
    sp.pipeline = pipeline_params("configs/vision.yaml", "configs/registration.yaml", false,
                                  render::CompositeMode::kDepth, scene->initial_r_W_hand());
    sp.seconds = seconds;
    sp.warm_up = warm_up;
    if (tweak) tweak(sp);
    params = sp;
    session = Session::create(*rig, *scene, *context, camera, models, sp);
  }
  std::unique_ptr<render::Context> context;
  strings::DeviceConfig config;
  std::array<hand::HandModel, 2> user, models;
  vision::Camera camera;
  std::unique_ptr<Scene> scene;
  std::unique_ptr<SimulatedRig> rig;
  SessionParams params;
  std::unique_ptr<Session> session;
};

}  // namespace spidar::session
