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
/// That is the script at script time s. The user plays it closed loop (script_schedule.hpp): it
/// watches the cube (track()) and checks what happened where a step should have ended —
///   - after each turn, once the right hand has let go (s = 5.7, 9.9): did the layer click into
///     its detent (the published turn count)? Missing turns are tried again by replaying the
///     regrasp-and-turn stretch 5.7 – 9.9, as long as the rest of the script still fits before
///     `deadline`; with all `turns` done it goes on to setting the cube down;
///   - while the cube is held up (s in 3.0 – 9.2): is it still in the hand? A cube that dropped
///     more than half the lift below where the holding hand carries it, for 0.15 s, is a slipped
///     grasp: both hands open and approach and grasp it again from s = 0.7, where it lies (at its
///     resting height, though the opening hands may carry it up for a moment), if the turns left
///     fit before `deadline` (the regrasp replays a turn; with that the last, on to the set-down).
///   - during each turn: has the held cube sunk in the holding hand (`sink` lower than when the
///     turn began)? Then the holding hand grips harder for the rest of the run (`firm_squeeze`).
/// Each jump in s is cross-faded over a fraction of a second, so the fingertips never jump.
///
/// It gives the eight fingertip goals (left thumb, index, middle, ring, then right; the simulated
/// device's FingertipSource) and, per hand, a nominal hand pose that goes with them (wrist pose
/// and a relaxed grip), which sim::UserHands uses as the prior of the user's hand posture.
/// Goals lie `squeeze` inside the faces, so the fingertips' impedance sets the grip force.
/// In a scene without a cube, p_W_cube and half describe the object to reach for (any box-like
/// object): the same motions grasp, lift, let go, grasp again and set it down, but the right hand
/// only twists it (kRigidTwistShare of the turn, and back). A rigid object held by the other hand
/// does not turn: a full quarter turn dragged the right fingertips against it until their caps
/// lay where the user's fingers could not follow. The simulated hands missed them by up to 3 mm
/// (`ground_truth.cap_residual_mm_max`, a 4 cm box off the centre; 0.75 mm with the twist). Not
/// turning at all kept the caps as well, but the right hand then held one pose for seconds, and
/// the size estimate, short of other poses, took its width to the −15 % bound
/// (docs/measurements.md, 2026-11-27, late night). On an object smaller than the cube the
/// fingertips of each hand keep the cube's spacing across each other, as far as the object's
/// faces allow: fingers do not shrink with the object.
///
/// The user watches the cube: with track() given, a hand approaching for a grasp takes the cube's
/// current pose (from the physics thread) as the frame of that grasp, so a cube that tilted or slid
/// while held is grasped where it is (up to its 90° symmetry about its vertical axis).
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "spidar/core/pose.hpp"
#include "spidar/core/seqlock.hpp"
#include "spidar/core/types.hpp"
#include "spidar/device/fingertip_source.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/hand/parameters.hpp"
#include "spidar/sim/script_schedule.hpp"

namespace spidar::sim {

/// The share of the turn (RubiksTaskParams::turn) by which the right hand twists an object that is
/// not a cube, while the left hand holds it.
inline constexpr double kRigidTwistShare = 1.0 / 3.0;

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
  double duration = 12.0;        ///< the script's length (script time) [s]
  int turns = 2;                 ///< layer turns to make (≥ 1)
  double deadline = 20.0;        ///< run time by which the user must be done: retries must fit [s]
  /// A user who feels the held cube sink in the holding (left) hand while the other turns a layer
  /// grips harder: once the cube is `sink` lower than when the turn began, the holding hand's
  /// goals go `firm_squeeze` deeper into the faces (over 0.2 s) for the rest of the run. 0 = never.
  double firm_squeeze = 0.004;   ///< [m]
  double sink = 0.002;           ///< [m]
  bool has_cube = true;          ///< a Rubik's cube (false: another object, held and twisted; no turns)
  /// On a cube, the holding (left) hand's ring finger presses on the cube's left face instead of
  /// its back (rubiks_task.cpp, contacts()): each finger then sits on a face its unit's strings can
  /// push it back from. Through the device in lockstep the layer turns twice at 8 of 8 placements
  /// (the cube turned −0.3 … 0.45 rad or moved 5 cm) against 3 of 8; in the demo the default
  /// user's contested pixels go from about 1.1 % to 0.2 % wrong. With fit_to_hands' margin at 0
  /// the long users (+10 % length) then miss the device's caps by 1.4–2.0 mm (their left index
  /// pressed past its passive range); with 0.1 rad every user ±10 % reaches them within 0.8 mm.
  /// The session's scripted user plays it so (session::ScriptedUserOptions); false here keeps
  /// the task as it was for a library user who builds it alone (docs/measurements.md, session 46).
  bool ring_on_side = false;
  /// The user's fingertips held with their own fingers' stiffness (sim/finger_hold.hpp) once
  /// fit_to_hands is called: the caps then yield to the displayed forces only where the fingers
  /// can follow them, so the user's hands reach the device's caps within their active ranges
  /// (cap residual ≤ 0.4 mm in the demo; isotropic fingertips push the fingers into their passive
  /// ranges instead, sim::UserHands). The fit puts the fingertips on the faces
  /// (they press along their compliant directions), keeps each hand on its layers, and the goals
  /// move no faster than max_goal_speed. Off by default: with it the grip is weaker for other hands
  /// (README: the users ±10 % made 1 of 2 turns in 8 of 8 runs).
  bool shaped_fingers = false;
  /// With shaped_fingers, how fast a fingertip goal may move [m/s]: a hand moves smoothly, so where
  /// the plan changes at once (a grasp frame taken from where the cube now is) the goals follow at
  /// this speed, and a stiff finger does not snap. The script's own motions stay below 0.15 m/s.
  double max_goal_speed = 0.5;
};

/// The cube's pose as the physics thread publishes it (plain data for core::Latest).
struct CubePoseSample {
  std::array<double, 3> p_W{};           ///< centre [m]
  std::array<double, 4> q_WC{1, 0, 0, 0};  ///< orientation (w, x, y, z)
  /// Completed quarter turns of the top layer so far, the layer the user turns (−1: not counted);
  /// another layer dragged along does not count as the user's turn.
  std::int32_t turns = -1;
};

/// How the closed-loop user is doing (published for the frame thread and the report).
struct TaskProgress {
  std::int32_t turns_planned = 0;  ///< layer turns the user sets out to make
  std::int32_t turns_seen = 0;     ///< completed turns at the user's last check
  std::int32_t attempts = 0;       ///< turn attempts started (planned turns + retries)
  std::int32_t retries_turn = 0;   ///< turns tried again after one that did not click
  std::int32_t retries_grasp = 0;  ///< grasps made again after the cube slipped
  bool gave_up = false;            ///< a retry was needed but no longer fitted before the deadline
  double firm_since_s = -1;        ///< run time the holding hand began to grip harder (−1: it did not)
};

class RubiksTask final : public device::FingertipSource {
 public:
  explicit RubiksTask(RubiksTaskParams p);
  /// Makes the script reachable by these hands (left, right: the user's own): each hand's
  /// touching positions (goals less their squeeze into the faces), in its grasp frame, are
  /// replaced by the nearest fingertip positions the hand can take (inverse kinematics along the
  /// script, every `dt_s`; linear in between); the squeeze is added back, so the grip is the
  /// script's. With shaped_fingers it also puts the touching positions on the faces, keeps each
  /// hand on its layers and gives the fingers' holds (holds()): the caps then yield to the
  /// displayed forces only where the fingers can follow them.
  /// Without it the goals are the script's contact layout, which a hand of another size may not
  /// reach (adjacent caps closer than fingers are wide): the user's fingers could then not be
  /// where the device's caps are. Call before the task is shared with other threads.
  ///
  /// `limit_margin_rad` (left hand, right hand): the fit keeps the finger joints this far inside
  /// their ranges [rad], and
  /// (with a margin > 0) side contacts on their hand's layers, clear of the top/middle boundary.
  /// With 0 the fitted layout has the index and ring abduction at their limits (the script's caps
  /// are closer together than fingers are), so where the device's caps actually are (pressed past
  /// the touching positions, pulled apart by their strings) is partly out of the active ranges:
  /// the user's fingers follow them into their passive ranges (UserHands). A margin of
  /// 0.1 rad makes them reachable on the lockstep physics (tests/sim/test_user_hands_physics.cpp:
  /// within 0.6 mm, both turns made) but spreads the fingers, which changes the grasp: in the
  /// demo (threads, strings) the second turn then failed in 4 of 4 runs with the back-face grasp.
  /// With the ring on the side (RubiksTaskParams::ring_on_side) it holds: the session fits the
  /// holding (left) hand with 0.1 rad, whose index its caps pushed past its passive range, and the
  /// turning hand with none (session::ScriptedUserOptions::fit_limit_margin_rad; with the margin
  /// there too, the right hand's estimated width ended 18–28 % wide for three users of five).
  void fit_to_hands(const std::array<hand::HandModel, 2>& hands, double dt_s,
                    const std::array<double, 2>& limit_margin_rad);
  /// fit_to_hands with the same margin for both hands.
  void fit_to_hands(const std::array<hand::HandModel, 2>& hands, double dt_s = 0.01,
                    double limit_margin_rad = 0.0) {
    fit_to_hands(hands, dt_s, std::array<double, 2>{limit_margin_rad, limit_margin_rad});
  }
  /// How far the fitted paths move the script's goals, per hand (max over the script) [m].
  const std::array<double, 2>& fit_shift_max_m() const { return fit_shift_max_; }
  /// Follow the cube's published pose (must outlive the task); nullptr = the start pose.
  void track(const core::Latest<CubePoseSample>* cube) { cube_ = cube; }
  /// Goals of the eight fingertips at run time t [s] (world, m). The user's clock: call from one
  /// thread (the simulated device's); it checks the task and publishes the schedule.
  void goals(double t_s, std::span<Vec3> p_W_goal) override;
  /// With fit_to_hands: each fingertip's stiffness shaped like the user's finger at the fitted
  /// pose of the last goals() call (sim/finger_hold.hpp), turned with its hand; else false.
  bool holds(std::span<device::FingertipHold> hold) override;
  /// Where the eight fingertips touch at time t (world, m): the goals less their squeeze into the
  /// faces (a finger stops at the face), in the grasp frames last published by goals().
  void touch_points(double t_s, std::span<Vec3> p_W) const;
  /// The nominal pose of one hand at time t (wrist in world, relaxed finger angles).
  hand::HandParams nominal(double t_s, hand::Side side) const;
  /// Name of the phase at run time t, from the scene ("turn 2 (top layer)" only with a cube).
  std::string phase(double t_s) const;
  /// The part of the task run time t belongs to, a fixed word for grouping frames in a report:
  /// "approach" (the hands reach, also again after a slip), "grasp", "lift", "turn", "regrasp" (the
  /// turning hand lets go, goes back and grasps again), "release" (the hands let go, the cube is set
  /// down), "withdraw", "done".
  std::string_view phase_kind(double t_s) const;
  /// Script time at run time t (the published schedule).
  double script_time(double t_s) const;
  /// True once the script has played to its end.
  bool finished(double t_s) const { return script_time(t_s) >= p_.duration; }
  /// The user's checks so far.
  TaskProgress progress() const;
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
  /// What goals() publishes for the other threads.
  struct Plan {
    ScriptSchedule schedule;
    TaskProgress progress;
    GraspFrames from_frames;  ///< the grasp frames when the newest segment started (its blend source)
  };
  /// The closed loop: checks the task at run time t with the cube as last seen; may start a
  /// segment of the schedule (servo thread).
  void update_plan(double t_s, const std::optional<CubePoseSample>& cube);
  /// After a turn, once the right hand has let go (`first`: after the first turn).
  void check_turns(double t_s, int turns_seen, bool first);
  /// Starts a segment at run time t from script time s0, blending from the present script time.
  void jump(double t_s, double s0, double blend_s, SegmentKind kind, int attempt, int turn);
  Plan read_plan() const;
  /// The newest grasp frames (published_), read again until no publish races the read: the
  /// servo thread's own copy (frames_) is not for other threads.
  GraspFrames read_frames() const;
  /// True while the cube is where a hand can take it: near its start place (not thrown off the
  /// table). Hands follow only such a cube.
  bool within_reach(const CubePoseSample& cube) const;
  HandState state(double t_s, hand::Side side, int finger) const;
  /// 0 = hand open, 1 = closed on the grasp.
  static double closeness(double t_s, hand::Side side);
  /// True while a hand approaches for a grasp: then it follows the cube's pose.
  static bool looks_for_grasp(double t_s, hand::Side side);
  /// `firm_m`: how much deeper the holding (left) hand presses, as far as it is closed [m].
  void goals_at(double t_s, const GraspFrames& frames, std::span<Vec3> p_W_goal,
                bool squeeze = true, double firm_m = 0.0) const;
  /// goals_at at run time t through the schedule (cross-fading during a segment's blend from
  /// where the previous segment was left, in the grasp frames of then).
  void scheduled_goals(const Plan& plan, double t_s, const GraspFrames& frames,
                       std::span<Vec3> p_W_goal, bool squeeze) const;
  /// The cross-fade of scheduled_goals: `goal` (at the segment's script time) blended from where
  /// the previous segment was left, during the segment's blend.
  void blend_goals(const Plan& plan, const ScriptSegment& seg, double t_s, const GraspFrames& frames,
                   std::span<Vec3> p_W_goal, bool squeeze, double firm_m) const;
  /// A point of `side`'s hand a share w of the way from `from` (script time s_from) to `to`
  /// (s_to) [m, world], along an arc about the cube's vertical axis in that hand's grasp frame,
  /// turning the way the script's yaw turns between the two.
  Vec3 around_cube(hand::Side side, double s_from, double s_to, const GraspFrames& frames, const Vec3& from,
                   const Vec3& to, double w) const;
  /// nominal() at script time s with these grasp frames.
  hand::HandParams nominal_at(double s, hand::Side side, const GraspFrames& frames) const;
  /// Finger f's (0..7) goal in its hand's grasp frame before the hand's yaw and lift: the
  /// script's contact path, or the fitted path when fit_to_hands was called.
  Vec3 path(double t_s, int f) const;
  Vec3 script_path(double t_s, int f) const;
  /// The part of script_path that presses into the face (the grip force through the fingertip's
  /// impedance): zero while open, `squeeze` along the face's inward normal when closed. A finger
  /// stops at the face; its touching position is script_path − squeeze_path.
  Vec3 squeeze_path(double t_s, int f) const;
  /// Where the squeeze puts finger f's goal relative to its touching position: squeeze_path as a
  /// force, k·squeeze_path with k the fingertip's softest stiffness, taken up by the finger's
  /// hold (fit_to_hands): C·squeeze_path with C its compliance relative to its softest direction.
  /// The contact then stops the fingertip at the touching position, pressing with the script's
  /// force, and the fingertip yields only where the finger can move (a goal straight into the
  /// face along a stiff direction would slide it sideways instead). Without a fit, squeeze_path.
  Vec3 pressing(double t_s, int f) const;
  /// Where script time t falls between the fitted samples (a table of n ≥ 2, every fit_dt_):
  /// sample k and the weight of sample k + 1.
  struct FitSample {
    std::size_t k;
    double w;
  };
  FitSample fit_sample(double t_s, std::size_t n) const;
  /// The fitted touching position of finger f at script time t (fit_to_hands), grasp frame.
  Vec3 fitted_touch(double t_s, int f) const;
  /// Outward normal of the face finger f (0..7) grasps, in its hand's grasp frame.
  Vec3 contact_normal(int f) const;
  /// The nominal pose of one hand in its grasp frame (before yaw and lift): the pose fitted to
  /// the hand's path when fit_to_hands was called, else script_nominal_local.
  hand::HandParams nominal_local(double t_s, hand::Side side) const;
  /// The script's relaxed grip around its contact layout, in the grasp frame.
  hand::HandParams script_nominal_local(double t_s, hand::Side side) const;
  RubiksTaskParams p_;
  const core::Latest<CubePoseSample>* cube_ = nullptr;
  GraspFrames frames_;                      ///< servo thread's copy
  core::Latest<GraspFrames> published_;     ///< for nominal()
  Plan plan_;                               ///< servo thread's copy
  core::Latest<Plan> published_plan_;       ///< for the other threads
  double prev_s_ = 0;                       ///< script time at the previous goals() call
  double prev_goal_t_ = -1;                 ///< run time of the previous goals() call (−1: none)
  std::array<Vec3, 8> prev_goal_ = zeros<Vec3, 8>();        ///< the goals it gave
  double drop_since_ = -1;                  ///< run time the cube was first seen dropped (−1: not)
  double turn_start_lift_ = -1;             ///< the held cube's lift when the current turn began [m] (−1: no turn)
  int turns_at_check_ = 0;                  ///< turns seen at the previous turn check
  /// Fitted fingertip paths (fit_to_hands): per hand, 4 fingertips every fit_dt_ seconds.
  std::array<std::vector<std::array<Vec3, 4>>, 2> fitted_;
  std::array<std::vector<hand::HandParams>, 2> fitted_q_;  ///< the poses that reach them
  /// The fingers' holds at those poses, in the grasp frame (before the hand's yaw).
  std::array<std::vector<std::array<device::FingertipHold, 4>>, 2> fitted_hold_;
  std::array<device::FingertipHold, 8> holds_{};  ///< servo thread: for the last goals()
  double fit_dt_ = 0.0;
  std::array<double, 2> fit_shift_max_{0.0, 0.0};
};

}  // namespace spidar::sim
