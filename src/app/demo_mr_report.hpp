#pragma once
/// What the mixed-reality demo records per frame, and its report: report.json, plot PNGs and the
/// printed summary.
#include <array>
#include <map>
#include <ostream>
#include <string>
#include <vector>

#include "spidar/device/servo_loop.hpp"
#include "spidar/physics/world.hpp"
#include "spidar/sim/frame_truth.hpp"
#include "spidar/sim/haptic_bridge.hpp"
#include "spidar/sim/rubiks_task.hpp"

namespace spidar::app {

struct MrFrame {
  double t_s = 0;              ///< script time of the exposure [s]
  double latency_ms = 0;       ///< exposure → composite ready [ms]
  double pipeline_ms = 0;      ///< frame pipeline cost [ms]
  double registration_ms = 0;  ///< both hands [ms]
  double preprocess_ms = 0;    ///< chroma key, bracelets, distance transform [ms]
  pipeline::FrameTimings stages;  ///< the main pipeline's stages [ms]
  double film_ms = 0;          ///< synthetic camera (simulation cost, not pipeline) [ms]
  double truth_ms = 0;         ///< ground-truth posture, comparison fit, metrics [ms]
  double output_ms = 0;        ///< video and keyframes [ms]
  /// [0]: the main registration, [1]: the comparison (silhouette term switched the other way).
  std::array<sim::FrameTruthMetrics, 2> truth{};
  bool compared = false;  ///< truth[1] measured in this frame
  /// The model's skin at the true pose with the user's sizes vs the real silhouette
  /// (sim::ModelCeiling); measured on compared frames (ceiling_measured).
  double ceiling_iou = 0;
  bool ceiling_measured = false;
  std::array<int, 2> iterations{};
  std::array<double, 2> truth_cap_residual_mm{};
  double lift_mm = 0, u_angle_deg = 0, d_angle_deg = 0;
  int turns = 0;
  std::array<double, 8> force_n{};
  double servo_rate_hz = 0, servo_jitter_max_us = 0;
};

struct MrTrace {
  std::vector<MrFrame> frames;
};

struct MrSummary {
  double seconds = 0, wall_s = 0;
  int dropped = 0;
  device::ServoStats servo;
  sim::PhysicsThreadStats physics;
  int turns = 0;
  sim::TaskProgress task;  ///< the scripted user's plan: turns planned, retries
  bool solved = false, has_cube = false;
  std::map<char, double> face_deg;  ///< each face layer's final angle [deg]
  std::string facelets, video_path, video_format, compositor, scene, user_hand;
  double user_length_m = 0, user_width_m = 0;  ///< the simulated user's true hand sizes
  bool main_silhouette = false;
  int width = 0, height = 0;
  std::string ended_by = "completed";  ///< completed | SIGINT | SIGTERM
  std::uint64_t mujoco_warnings = 0;   ///< MuJoCo warnings in the process (physics::mujoco_warnings)
  std::vector<physics::World::WarningCount> mujoco_warning_kinds;  ///< the world's, by kind
  std::string mujoco_log;              ///< OUT/mujoco_log.txt when there were warnings
};

/// Writes report.json and the plots into `out`, prints the summary; returns the exit code.
int write_mr_report(const std::string& out, const MrTrace& trace, const MrSummary& summary,
                    std::ostream& os);

}  // namespace spidar::app
