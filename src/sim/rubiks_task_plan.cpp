// The Rubik's cube user's closed loop: the checks it makes while playing its script, the retries
// they start, and the phase names (rubiks_task.hpp, script_schedule.hpp).
#include <algorithm>
#include <cmath>
#include <thread>

#include "spidar/sim/rubiks_task.hpp"

namespace spidar::sim {
namespace {

// Script times of the steps the loop checks or jumps to (the script in rubiks_task.hpp).
constexpr double kHeldFrom = 3.0;      ///< the cube is held up from here …
constexpr double kHeldUntil = 9.2;     ///< … until it is set down
constexpr double kFirstCheck = 5.7;    ///< the first turn done and the right hand open
constexpr double kLaterCheck = 9.9;    ///< a later turn done and the right hand open
constexpr double kRegraspFrom = 0.7;   ///< a new approach: the hands nearly open at the faces, following the cube
constexpr double kWithdrawFrom = 11.3; ///< both hands withdraw

constexpr double kTurnBlend = 0.6;     ///< [s] cross-fade into a new turn attempt
/// [s] the same from the later check, where the left hand must lift the set-down cube again
/// while the right hand swings back a turn: no faster than the script's own lift and return.
constexpr double kLaterTurnBlend = 1.2;
constexpr double kRegraspBlend = 0.8;  ///< [s] cross-fade from a lost grasp to the approach
constexpr double kDropHold = 0.3;      ///< [s] a drop must last this long to count as a slip
constexpr double kDroppedLift = 0.15;  ///< a cube below this share of the script's lift is down (3 mm of 20)

/// [s] from a slip to the script's end, at most (the cross-fades counted in full), when the grasp
/// is made again from kRegraspFrom with `remaining` planned turns still to make: the regrasp
/// replays the first turn's stretch, and when that makes the last turn the first check skips to
/// the set-down (check_turns), else the script plays on from there.
double regrasp_time_s(double duration, int remaining) {
  if (remaining <= 1) return kRegraspBlend + (kFirstCheck - kRegraspFrom) + kTurnBlend + (duration - kLaterCheck);
  return kRegraspBlend + (duration - kRegraspFrom);
}

}  // namespace

bool RubiksTask::within_reach(const CubePoseSample& c) const {
  constexpr double kReach = 0.08;  // [m] horizontally from the start place
  const double dx = c.p_W[0] - p_.p_W_cube.x(), dy = c.p_W[1] - p_.p_W_cube.y();
  const double dz = c.p_W[2] - p_.p_W_cube.z();
  return std::hypot(dx, dy) <= kReach && dz > -2.0 * p_.half && dz < 0.15;
}

RubiksTask::Plan RubiksTask::read_plan() const {
  // Published since construction, so a read fails only while publishes keep racing it (the
  // servo thread's, under a slow build such as TSan's): read again rather than fall back to
  // another plan for this call.
  for (;;) {
    if (auto p = published_plan_.read()) return *p;
    std::this_thread::yield();
  }
}

RubiksTask::GraspFrames RubiksTask::read_frames() const {
  for (;;) {  // as read_plan: published since construction
    if (auto f = published_.read()) return *f;
    std::this_thread::yield();
  }
}

double RubiksTask::script_time(double t_run) const { return read_plan().schedule.script_time(t_run); }

TaskProgress RubiksTask::progress() const { return read_plan().progress; }

void RubiksTask::jump(double t_run, double s0, double blend_s, SegmentKind kind, int attempt, int turn) {
  ScriptSegment seg;
  seg.t0_s = t_run;
  seg.s0_s = s0;
  seg.s_from_s = plan_.schedule.script_time(t_run);
  seg.blend_s = blend_s;
  seg.kind = kind;
  seg.attempt = attempt;
  seg.turn = turn;
  plan_.schedule.start(seg);
  plan_.from_frames = frames_;
}

void RubiksTask::check_turns(double t_run, int seen, bool first) {
  TaskProgress& pr = plan_.progress;
  pr.turns_seen = seen;
  const bool progressed = seen > turns_at_check_;
  turns_at_check_ = seen;
  const int attempt = plan_.schedule.newest().attempt;
  if (seen >= pr.turns_planned) {
    // Done turning: after the first turn skip the regrasp-and-turn stretch (the right hand is
    // open at both ends); after a later one the script goes on to set the cube down anyway.
    if (first) jump(t_run, kLaterCheck, kTurnBlend, SegmentKind::kSkip, attempt, seen + 1);
    return;
  }
  // Another attempt: a retry when this one did not click, else the next planned turn.
  const SegmentKind kind = progressed ? SegmentKind::kNextTurn : SegmentKind::kRetryTurn;
  if (first) {  // the script's own next stretch is that attempt
    ++pr.attempts;
    if (!progressed) {  // the same turn again: a segment in place, to name it so
      ++pr.retries_turn;
      const double s_now = plan_.schedule.script_time(t_run);
      jump(t_run, s_now, 0.0, SegmentKind::kRetryTurn, pr.attempts, seen + 1);
    }
    return;
  }
  // The rest of the script from the regrasp must fit before the deadline.
  if (t_run + kLaterTurnBlend + (p_.duration - kFirstCheck) > p_.deadline) {
    pr.gave_up = true;
    return;
  }
  if (!progressed) ++pr.retries_turn;
  ++pr.attempts;
  jump(t_run, kFirstCheck, kLaterTurnBlend, kind, pr.attempts, seen + 1);
}

void RubiksTask::update_plan(double t_run, const std::optional<CubePoseSample>& cube) {
  const double s = plan_.schedule.script_time(t_run);
  bool changed = false;
  if (p_.has_cube && cube) {
    // A slipped grasp: the cube back down near where it rested when the holding (left) hand
    // took it, while the script holds it up. (Not "lower than the script lifts it": a cube held
    // by compliant fingertips hangs lower than the goals; only a fall is a slip.)
    if (!within_reach(*cube)) {
      // The cube left the scene (off the table, thrown): nothing to grasp again. Withdraw.
      if (plan_.schedule.newest().kind != SegmentKind::kGiveUp && s < kWithdrawFrom) {
        plan_.progress.gave_up = true;
        jump(t_run, kWithdrawFrom, kRegraspBlend, SegmentKind::kGiveUp, plan_.schedule.newest().attempt,
             plan_.schedule.newest().turn);
        changed = true;
      }
    } else if (s >= kHeldFrom && s < kHeldUntil) {
      const double lifted = cube->p_W[2] - frames_.p_W[0][2];
      if (lifted < kDroppedLift * state(s, hand::Side::kLeft, 0).lift) {
        if (drop_since_ < 0) drop_since_ = t_run;
      } else {
        drop_since_ = -1;
      }
      if (drop_since_ >= 0 && t_run - drop_since_ >= kDropHold) {
        drop_since_ = -1;
        const int attempt = plan_.progress.attempts + 1;
        // The turns made so far stay made: only the ones left need time (a slip in the second
        // turn, at 8.6 s, leaves room for one more, not for the whole script again).
        const int remaining = plan_.progress.turns_planned - std::max(cube->turns, plan_.progress.turns_seen);
        if (t_run + regrasp_time_s(p_.duration, remaining) <= p_.deadline) {
          ++plan_.progress.retries_grasp;
          ++plan_.progress.attempts;
          jump(t_run, kRegraspFrom, kRegraspBlend, SegmentKind::kRegrasp, attempt, plan_.progress.turns_seen + 1);
        } else {
          plan_.progress.gave_up = true;
          jump(t_run, kWithdrawFrom, kRegraspBlend, SegmentKind::kGiveUp, attempt - 1, plan_.schedule.newest().turn);
        }
        changed = true;
      }
    } else {
      drop_since_ = -1;
    }
    // A cube sinking in the holding hand during a turn: grip harder (once).
    const bool turning = (s >= kHeldFrom && s < 5.0) || (s >= 7.2 && s < 9.2);
    if (!turning) {
      turn_start_lift_ = -1;
    } else if (p_.firm_squeeze > 0 && plan_.progress.firm_since_s < 0) {
      const double lifted = cube->p_W[2] - frames_.p_W[0][2];
      if (turn_start_lift_ < 0) turn_start_lift_ = lifted;
      if (lifted < turn_start_lift_ - p_.sink) {
        plan_.progress.firm_since_s = t_run;
        changed = true;
      }
    }
    if (!changed && cube->turns >= 0) {
      if (prev_s_ < kFirstCheck && s >= kFirstCheck) {
        check_turns(t_run, cube->turns, true);
        changed = true;
      }
      if (prev_s_ < kLaterCheck && s >= kLaterCheck) {
        check_turns(t_run, cube->turns, false);
        changed = true;
      }
    }
  }
  prev_s_ = plan_.schedule.script_time(t_run);
  if (changed) published_plan_.publish(plan_);
}

std::string RubiksTask::phase(double t_run) const {
  const ScriptSchedule sched = read_plan().schedule;
  const ScriptSegment& seg = sched.at(t_run);
  const double s = sched.script_time(t_run);
  // The turn a turn phase makes: a segment from before the first turn phase makes its own turn
  // there and the next one in the second turn phase; a later one makes its own in the second.
  const int first_turn = seg.s0_s < kHeldFrom ? seg.turn : seg.turn - 1;
  const bool again = seg.kind == SegmentKind::kRegrasp;
  const bool cube = p_.has_cube;
  auto turn = [&](int n) {
    std::string name = cube ? "turn " + std::to_string(n) + " (top layer)" : "twist the object";
    if (cube && seg.kind == SegmentKind::kRetryTurn && s >= kFirstCheck) name += ", again";
    return name;
  };
  if (s < 1.0) return again ? (cube ? "approach the cube again" : "reach again") : (cube ? "approach" : "reach");
  if (s < 2.0) return again ? "grasp again" : "grasp";
  if (s < kHeldFrom) return "lift";
  if (s < 5.0) return turn(first_turn);
  if (s < kFirstCheck) return "right hand lets go";
  if (s < 6.5) return "right hand goes back";
  if (s < 7.2) return "right hand grasps";
  if (s < kHeldUntil) return turn(first_turn + 1);
  if (s < kLaterCheck) return cube ? "let go, set the cube down" : "let go, set it down";
  if (s < 10.6) return "left hand lets go";
  if (s < kWithdrawFrom) return "right hand turns back";
  if (s < p_.duration) return "withdraw";
  return "done";
}

std::string_view RubiksTask::phase_kind(double t_run) const {
  const double s = read_plan().schedule.script_time(t_run);
  if (s < 1.0) return "approach";
  if (s < 2.0) return "grasp";
  if (s < kHeldFrom) return "lift";
  if (s < 5.0) return p_.has_cube ? "turn" : "twist";
  if (s < 7.2) return "regrasp";
  if (s < 9.2) return p_.has_cube ? "turn" : "twist";
  if (s < kWithdrawFrom) return "release";
  if (s < p_.duration) return "withdraw";
  return "done";
}

}  // namespace spidar::sim
