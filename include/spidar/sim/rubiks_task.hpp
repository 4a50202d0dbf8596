#pragma once
/// The scripted user of the mixed-reality demo: both hands perform the Rubik's cube task.
///
///   0.0 – 1.0  hands approach           1.0 – 2.0  both hands close on the cube
///   2.0 – 3.0  lift: the left hand holds the two lower layers, the right hand the top layer
///   3.0 – 5.0  turn 1: the right hand turns the top layer by +turn about +z (past 90°, clicks)
///   5.0 – 5.7  the right hand lets go, the left hand holds the cube up
///   5.7 – 6.5  the right hand goes back  6.5 – 7.2  it grasps the top layer again
///   7.2 – 9.2  turn 2: the top layer by +turn again (U2 in all)
///   9.2 – 9.9  the right hand lets go, the left hand sets the cube down (to a quarter of the
///              lift: the cube may have slipped a little in the hand)
///   9.9 – 10.6 the left hand lets go
///  10.6 – 11.3 the right hand turns back 11.3 – 12.0 both hands withdraw
///
/// It gives the eight fingertip goals (left thumb, index, middle, ring, then right; the simulated
/// device's FingertipSource) and, per hand, a nominal hand pose that goes with them (wrist pose
/// and a relaxed grip), which sim::UserHands uses as the prior of the user's hand posture.
/// Goals lie `squeeze` inside the faces, so the fingertips' impedance sets the grip force.
/// In a scene without a cube, p_W_cube and half describe the object to reach for (any box-like
/// object): the same motions then grasp, push and turn it.
///
/// The user watches the cube: with track() given, a hand approaching for a grasp takes the cube's
/// current pose (from the physics thread) as the frame of that grasp, so a cube that tilted or slid
/// while held is grasped where it is (up to its 90° symmetry about its vertical axis).
#include <array>
#include <span>
#include <vector>

#include "spidar/core/pose.hpp"
#include "spidar/core/seqlock.hpp"
#include "spidar/core/types.hpp"
#include "spidar/device/fingertip_source.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/hand/parameters.hpp"

namespace spidar::sim {

struct RubiksTaskParams {
  Vec3 p_W_cube = Vec3::Zero();  ///< cube centre at the start [m]
  double half = 0.0285;          ///< half the cube's size [m]
  double pitch = 0.019;          ///< layer pitch [m]
  double proxy_radius = 0.008;   ///< [m]
  double squeeze = 0.012;        ///< goal depth inside the faces (turning hand) [m]
  double hold_squeeze = 0.012;   ///< the same for the holding (left) hand: it must resist the turn [m]
  double lift = 0.02;            ///< [m]
  double withdraw = 0.06;        ///< how far the hands start and end away from the grasp [m]
  double turn = 1.75;            ///< [rad] per turn, past 90° so that the detent finishes the click
  double duration = 12.0;        ///< [s]
};

/// The cube's pose as the physics thread publishes it (plain data for core::Latest).
struct CubePoseSample {
  std::array<double, 3> p_W{};           ///< centre [m]
  std::array<double, 4> q_WC{1, 0, 0, 0};  ///< orientation (w, x, y, z)
};

class RubiksTask final : public device::FingertipSource {
 public:
  explicit RubiksTask(RubiksTaskParams p);
  /// Makes the script reachable by these hands (left, right: the user's own): each hand's
  /// touching positions (goals less their squeeze into the faces), in its grasp frame, are
  /// replaced by the nearest fingertip positions the hand can take (inverse kinematics along the
  /// script, every `dt_s`; linear in between); the squeeze is added back, so the grip is the
  /// script's.
  /// Without it the goals are the script's contact layout, which a hand of another size may not
  /// reach (adjacent caps closer than fingers are wide): the user's fingers could then not be
  /// where the device's caps are. Call before the task is shared with other threads.
  void fit_to_hands(const std::array<hand::HandModel, 2>& hands, double dt_s = 0.01);
  /// How far the fitted paths move the script's goals, per hand (max over the script) [m].
  const std::array<double, 2>& fit_shift_max_m() const { return fit_shift_max_; }
  /// Follow the cube's published pose (must outlive the task); nullptr = the start pose.
  void track(const core::Latest<CubePoseSample>* cube) { cube_ = cube; }
  /// Goals of the eight fingertips at time t [s] (world, m).
  void goals(double t_s, std::span<Vec3> p_W_goal) override;
  /// Where the eight fingertips touch at time t (world, m): the goals less their squeeze into the
  /// faces (a finger stops at the face), in the grasp frames last published by goals().
  void touch_points(double t_s, std::span<Vec3> p_W) const;
  /// The nominal pose of one hand at time t (wrist in world, relaxed finger angles).
  hand::HandParams nominal(double t_s, hand::Side side) const;
  /// Name of the phase at time t (progress output).
  static const char* phase(double t_s);
  /// Layer turns the script performs (completed when the detent clicks).
  static constexpr int kTurns = 2;
  const RubiksTaskParams& params() const { return p_; }

 private:
  struct HandState {
    Vec3 offset = Vec3::Zero();  ///< fingertip displacement from the grasp, cube frame [m]
    double yaw = 0;              ///< rotation of the hand about the cube's vertical axis [rad]
    double lift = 0;             ///< [m]
  };
  /// Where each hand's grasp is: the cube's pose when the hand last was open, and the script's
  /// lift at that time (plain data: published by the servo thread, read by the frame thread).
  struct GraspFrames {
    std::array<std::array<double, 3>, 2> p_W{};
    std::array<std::array<double, 4>, 2> q_WG{};
    std::array<double, 2> lift{};
  };
  HandState state(double t_s, hand::Side side, int finger) const;
  /// 0 = hand open, 1 = closed on the grasp.
  static double closeness(double t_s, hand::Side side);
  /// True while a hand approaches for a grasp: then it follows the cube's pose.
  static bool looks_for_grasp(double t_s, hand::Side side);
  void goals_at(double t_s, const GraspFrames& frames, std::span<Vec3> p_W_goal,
                bool squeeze = true) const;
  /// Finger f's (0..7) goal in its hand's grasp frame before the hand's yaw and lift: the
  /// script's contact path, or the fitted path when fit_to_hands was called.
  Vec3 path(double t_s, int f) const;
  Vec3 script_path(double t_s, int f) const;
  /// The part of script_path that presses into the face (the grip force through the fingertip's
  /// impedance): zero while open, `squeeze` along the face's inward normal when closed. A finger
  /// stops at the face; its touching position is script_path − squeeze_path.
  Vec3 squeeze_path(double t_s, int f) const;
  /// The nominal pose of one hand in its grasp frame (before yaw and lift): the pose fitted to
  /// the hand's path when fit_to_hands was called, else script_nominal_local.
  hand::HandParams nominal_local(double t_s, hand::Side side) const;
  /// The script's relaxed grip around its contact layout, in the grasp frame.
  hand::HandParams script_nominal_local(double t_s, hand::Side side) const;
  RubiksTaskParams p_;
  const core::Latest<CubePoseSample>* cube_ = nullptr;
  GraspFrames frames_;                      ///< servo thread's copy
  core::Latest<GraspFrames> published_;     ///< for nominal()
  /// Fitted fingertip paths (fit_to_hands): per hand, 4 fingertips every fit_dt_ seconds.
  std::array<std::vector<std::array<Vec3, 4>>, 2> fitted_;
  std::array<std::vector<hand::HandParams>, 2> fitted_q_;  ///< the poses that reach them
  double fit_dt_ = 0.0;
  std::array<double, 2> fit_shift_max_{0.0, 0.0};
};

}  // namespace spidar::sim
