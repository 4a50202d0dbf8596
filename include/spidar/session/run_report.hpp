#pragma once
/// The run report of a scored session (the mixed-reality demo): what it records per frame, and
/// report.json, frames.csv, the plot PNGs and the printed summary built from it.
#include <array>
#include <map>
#include <ostream>
#include <string>
#include <vector>

#include "spidar/core/thread_name.hpp"
#include "spidar/device/servo_loop.hpp"
#include "spidar/physics/world.hpp"
#include "spidar/session/truth_scorer.hpp"
#include "spidar/sim/frame_truth.hpp"
#include "spidar/sim/haptic_bridge.hpp"
#include "spidar/sim/rubiks_task.hpp"

namespace spidar::session {

/// Per frame and per run: the ground-truth scorer's trace (session::TruthScorer).
using MrFrame = TruthFrame;
using MrTrace = TruthTrace;

struct MrSummary {
  double seconds = 0, wall_s = 0;
  int dropped = 0;        ///< delivered by the camera but not processed (the frame thread was busy)
  int camera_skipped = 0;  ///< exposures the simulated camera itself fell behind on
  /// Times the frame thread found every output slot taken and waited for the output thread
  /// (AsyncSinks::waits), and for how long in all [ms].
  std::uint64_t output_waits = 0;
  double output_wait_ms = 0;
  bool frame_realtime = false;  ///< the frame thread ran at SCHED_FIFO (SessionSummary::frame_realtime)
  device::ServoStats servo;
  sim::PhysicsThreadStats physics;
  int turns = 0;        ///< completed quarter turns of the top layer, the one the user turns
  int other_turns = 0;  ///< quarter turns of the other faces (a layer dragged along)
  sim::TaskProgress task;  ///< the scripted user's plan: turns planned, retries
  bool solved = false, has_cube = false;
  std::map<char, double> face_deg;  ///< each face layer's final angle [deg]
  std::string facelets, video_path, video_format, compositor, scene, user_hand;
  std::string user_profile;  ///< the hands YAML profile the simulated user has (user_hand's)
  double user_length_m = 0, user_width_m = 0;  ///< the simulated user's true hand sizes
  /// The simulated user's fingertip reach beyond the caps (−fingertip_offset.y) [m]; 0 = unknown.
  double user_cap_reach_m = 0;
  bool main_silhouette = false;
  bool personalised = false;  ///< the registration estimated the hands' sizes online
  bool bending_wrists = false;  ///< the simulated user's forearms point at fixed elbows
  bool shaped_fingers = false;  ///< the simulated user's fingertips held by their own fingers' stiffness
  bool ring_on_side = false;    ///< the simulated user's left ring finger on the cube's left face
  double fit_margin_rad = 0.0;  ///< the script fitted this far inside the holding hand's joint ranges [rad]
  int width = 0, height = 0;
  /// Each trace frame's part of the task (sim::RubiksTask::phase_kind), in trace order: the report
  /// gives the registration and the contested pixels per part (registration.by_phase) and
  /// frames.csv a `phase` column. Empty: not known (the figures over the whole run only).
  std::vector<std::string> phases;
  std::string ended_by = "completed";  ///< completed | SIGINT | SIGTERM
  std::uint64_t mujoco_warnings = 0;   ///< MuJoCo warnings in the process (physics::mujoco_warnings)
  std::vector<physics::World::WarningCount> mujoco_warning_kinds;  ///< the world's, by kind
  std::string mujoco_log;              ///< OUT/mujoco_log.txt when there were warnings
  std::vector<core::ThreadCpu> thread_cpu;  ///< SessionSummary::thread_cpu (report.json `threads`)
};

/// Writes report.json and the plots into `out`, prints the summary; returns the exit code.
int write_mr_report(const std::string& out, const MrTrace& trace, const MrSummary& summary,
                    std::ostream& os);

}  // namespace spidar::session
