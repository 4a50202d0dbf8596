// A session on the simulated rig recorded by SessionRecorder (PNG frames) and played back as a
// RecordingRig through a second Session: every recorded frame is fitted again through the same
// FramePipeline path to the same fits, and the recording holds the servo's tensions and motor
// commands as the loop published them.
#include <gtest/gtest.h>

#include <map>

#include "after_frames.hpp"
#include "recording_test_support.hpp"
#include "spidar/render/context.hpp"
#include "spidar/session/recording_rig.hpp"
#include "spidar/session/replay_report.hpp"
#include "spidar/session/rig.hpp"
#include "spidar/session/rig_inputs.hpp"
#include "spidar/session/session.hpp"
#include "spidar/session/session_recorder.hpp"
#include "spidar/strings/device_config.hpp"
#include "spidar/vision/camera_config.hpp"

namespace spidar::session::testing {
namespace {

/// Each frame's fitted hand parameters, by the frames.csv row it came from (live: the index).
struct FitTrace final : FrameSink {
  explicit FitTrace(const RecordingRig* rig = nullptr) : rig_(rig) {}
  void on_frame(const FrameEvent& e) override {
    const std::size_t row = rig_ != nullptr ? rig_->row() : static_cast<std::size_t>(e.index);
    q[row] = {e.result->hands[0].q, e.result->hands[1].q};
  }
  const RecordingRig* rig_;
  std::map<std::size_t, std::array<hand::ParamVec, 2>> q;
};

/// Records a session of the simulated rig filmed by `camera` (320×240), replays it through a
/// second session and checks that every frame is fitted again to the same fits.
void record_and_replay(const vision::Camera& camera, const char* folder) {
  TempFolder d(folder);
  const fs::path dir = d.path() / "rec";
  auto ctx = render::Context::create_headless();
  ASSERT_TRUE(ctx) << ctx.error().message;
  const auto config = strings::load_device_config("configs/spidar8.yaml");
  const auto user = hand_models("configs/hands.yaml", "user", true);
  const auto models = hand_models("configs/hands.yaml", "model", false);
  auto scene = Scene::load("scenes/rubiks_cube.xml", user).value();
  SessionParams sp;
  sp.servo.rate_hz = 1000;
  sp.servo.force_timeout_s = 0.05;
  sp.pipeline = pipeline_params("configs/vision.yaml", "configs/registration.yaml", false,
                                render::CompositeMode::kDepth, scene->initial_r_W_hand());
  // The live run ends after kLiveFrames frames (a slow, loaded or sanitised run takes longer, not
  // fewer frames); its seconds are only a backstop.
  constexpr std::size_t kLiveFrames = 20;
  sp.seconds = 30.0;
  // Personalise the hands' sizes often enough that they change within these frames: the
  // recording then holds sizes that move, and the replay must reach the same ones frame by frame.
  sp.pipeline.personalise_shape = true;
  sp.pipeline.shape_estimator.min_pose_change = 0.02;
  sp.pipeline.shape_estimator.min_keyframes = 2;
  sp.pipeline.shape_estimator.solve_every = 2;
  sp.pipeline.shape_estimator.shared_hands = true;  // either hand's keyframes move the sizes (few frames under ASan)
  // Each re-estimate applied where it is made (not 5 frames later on its own thread), so that the
  // sizes move within the run's few frames.
  sp.pipeline.shape_estimator.apply_after_frames = 0;

  // --- live, recorded ---
  FitTrace live;
  {
    SimulatedRigParams rp;
    rp.seed = 5;
    rp.fps = 30;
    SimulatedRig rig(config, *scene, camera, user, rp);
    RecordingDevice recording_device(rig.device());
    auto session = Session::create(rig, *scene, **ctx, camera, models, sp, &recording_device);
    RecorderSetup setup;
    setup.config_yaml = "recorded by a test\n";
    setup.width = 320;
    setup.height = 240;
    setup.fps = 30;
    setup.string_count = config.string_count();
    setup.finger_count = 8;
    setup.initial_r_W_hand = scene->initial_r_W_hand();
    setup.device_name = rig.name();
    SessionRecorder recorder(dir.string(), FrameStore::kPng, setup, recording_device, session->servo());
    session->add_sink(live);
    session->add_sink(recorder);
    session->run(after_frames(kLiveFrames, [&] { return live.q.size(); }));
    ASSERT_EQ(recorder.error(), "");
  }
  ASSERT_GT(live.q.size(), 0u) << "the live session processed no frame";

  // --- played back ---
  Recording rec = read_recording(dir.string());
  ASSERT_EQ(rec.frames.size(), live.q.size());
  ASSERT_FALSE(rec.fingertips.empty());
  // The servo's outputs as published: a solved cycle holds every string at t_min or more and
  // commands its motors (a cycle without a solve, e.g. a stall, may show 0).
  const auto limits = config.effective_limits();
  int solved = 0;
  for (const device::FingertipSample& s : rec.fingertips) {
    ASSERT_EQ(s.string_count, config.string_count());
    bool all = true;
    for (int i = 0; i < s.string_count; ++i) {
      const auto k = static_cast<std::size_t>(i);
      all = all && s.tension[k] >= limits.t_min - 1e-9 && s.tension[k] <= limits.t_max + 1e-9 && s.command[k] > 0;
    }
    solved += all ? 1 : 0;
  }
  EXPECT_GT(solved, 0);
  RecordingRig rig(std::move(rec), 320, 240);
  SessionParams replay = sp;
  replay.warm_up = false;
  replay.seconds = 0;
  auto session = Session::create(rig, *scene, **ctx, camera, models, replay);
  FitTrace replayed(&rig);
  ReplayScorer scorer(rig);
  session->add_sink(replayed);
  session->add_sink(scorer);
  const SessionSummary summary = session->run();
  EXPECT_EQ(summary.ended_by, "camera ended");
  EXPECT_EQ(rig.decode_errors(), 0);
  ASSERT_EQ(replayed.q.size(), live.q.size());
  double max_dq = 0;
  for (const auto& [row, q] : live.q)
    for (int h = 0; h < 2; ++h) max_dq = std::max(max_dq, (replayed.q.at(row)[h] - q[h]).cwiseAbs().maxCoeff());
  EXPECT_LT(max_dq, 1e-9);
  // The scorer compares with fits.csv the same way.
  EXPECT_EQ(scorer.figures().compared_hands, 2 * static_cast<int>(live.q.size()));
  EXPECT_LT(scorer.figures().max_dq, 1e-9);
  // fits.csv holds the sizes each live fit used; they moved, and the replay's follow them exactly.
  const Recording& played = rig.recording();
  double moved_mm = 0;
  for (const auto& frame : played.fits)
    for (const FitRow& f : frame) {
      const hand::HandDimensions& start = models[static_cast<std::size_t>(f.hand)].shape.dimensions;
      moved_mm = std::max({moved_mm, std::abs(f.length_m - start.length) * 1e3, std::abs(f.width_m - start.width) * 1e3});
    }
  EXPECT_GT(moved_mm, 0.01) << "the sizes never changed: the test does not exercise them";
  EXPECT_EQ(scorer.figures().compared_sizes, 2 * static_cast<int>(live.q.size()));
  EXPECT_LT(scorer.figures().max_dsize_mm, 1e-9);
}

TEST(RecordingRig, ASimulatedSessionRecordedAsPngReplaysThroughASessionToTheSameFits) {
  record_and_replay(scaled_camera(vision::load_camera_file("configs/camera.yaml").camera, 320, 240),
                    "replay_session");
}

// Through a lens: the recording keeps the frames as the sensor gave them (FrameEvent::sensor_bgr),
// and the replay undistorts them as the live session did. (Had it kept the undistorted frames,
// the replay would undistort them twice and fit other poses.)
TEST(RecordingRig, ASessionThroughALensReplaysToTheSameFits) {
  vision::Camera camera = scaled_camera(vision::load_camera_file("configs/camera.yaml").camera, 320, 240);
  vision::Intrinsics k = camera.intrinsics();
  k.distortion = {-0.28, 0.09, 0.0008, -0.0005, 0.0};
  camera.set_intrinsics(k);
  record_and_replay(camera, "replay_session_lens");
}

}  // namespace
}  // namespace spidar::session::testing
