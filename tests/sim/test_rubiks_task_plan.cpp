// The scripted user's closed loop: it checks the cube where a step should have ended and retries
// what did not work, within the run's deadline, without a jump in the fingertips.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <set>
#include <string>

#include "spidar/core/seqlock.hpp"
#include "spidar/core/units.hpp"
#include "spidar/sim/rubiks_task.hpp"

namespace spidar::sim {
namespace {

/// The cube as a physics thread would publish it: where the script carries it (at the start
/// pose, lifted by `lift` m) with `turns` completed turns.
CubePoseSample cube_at(const RubiksTaskParams& p, double lift, int turns) {
  CubePoseSample c;
  c.p_W = {p.p_W_cube.x(), p.p_W_cube.y(), p.p_W_cube.z() + lift};
  c.turns = turns;
  return c;
}

struct Played {
  double max_step_m = 0;        ///< largest fingertip goal step between 1 ms calls
  double finished_at_s = -1;    ///< run time the script reached its end (−1: not by the end)
  double min_script_jump = 0;   ///< most negative script-time step (a jump back)
};

/// Plays the task from 0 to t_end at 1 kHz; `world(t, s)` says what the cube looks like at run
/// time t and script time s (published before each call, as the physics thread would).
Played play(RubiksTask& task, core::Latest<CubePoseSample>& feed, double t_end,
         const std::function<CubePoseSample(double, double)>& world) {
  Played r;
  std::array<Vec3, 8> prev, g;
  double s_prev = 0;
  feed.publish(world(0.0, 0.0));
  task.goals(0.0, prev);
  for (int k = 1; k <= static_cast<int>(std::lround(t_end * 1000)); ++k) {
    const double t = k * 1e-3;
    feed.publish(world(t, task.script_time(t)));
    task.goals(t, g);
    for (int f = 0; f < 8; ++f) r.max_step_m = std::max(r.max_step_m, (g[f] - prev[f]).norm());
    prev = g;
    const double s = task.script_time(t);
    r.min_script_jump = std::min(r.min_script_jump, s - s_prev - 1e-3);
    s_prev = s;
    if (r.finished_at_s < 0 && task.finished(t)) r.finished_at_s = t;
  }
  return r;
}

/// The lift the script gives the cube at script time s (rubiks_task.hpp: up 2–3 s, held, set
/// down to a quarter 9.2–9.9).
double script_lift(const RubiksTaskParams& p, double s) {
  auto ramp = [](double t, double t0, double t1) {
    const double x = std::clamp((t - t0) / (t1 - t0), 0.0, 1.0);
    return x * x * (3 - 2 * x);
  };
  return p.lift * (ramp(s, 2.0, 3.0) - 0.75 * ramp(s, 9.2, 9.9));
}

TEST(ClosedLoopUser, EveryTurnClicksSoTheScriptPlaysOnceWithoutRetries) {
  RubiksTask task({});
  core::Latest<CubePoseSample> feed;
  task.track(&feed);
  const RubiksTaskParams p = task.params();
  // The layer clicks at 5.3 s and 9.5 s of script time.
  const Played r = play(task, feed, 14.0, [&](double, double s) {
    return cube_at(p, script_lift(p, s), (s >= 5.3) + (s >= 9.5));
  });
  const TaskProgress pr = task.progress();
  EXPECT_EQ(pr.turns_planned, 2);
  EXPECT_EQ(pr.turns_seen, 2);
  EXPECT_EQ(pr.attempts, 2);
  EXPECT_EQ(pr.retries_turn, 0);
  EXPECT_EQ(pr.retries_grasp, 0);
  EXPECT_FALSE(pr.gave_up);
  EXPECT_NEAR(r.finished_at_s, p.duration, 2e-3);  // open loop when all goes well
  EXPECT_GE(r.min_script_jump, -1e-9);
  EXPECT_LT(r.max_step_m, 0.0005);
}

TEST(ClosedLoopUser, ATurnThatDoesNotClickIsTriedAgain) {
  RubiksTask task({});
  core::Latest<CubePoseSample> feed;
  task.track(&feed);
  const RubiksTaskParams p = task.params();
  // The first turn slips (no click); the second attempt clicks, and so does the third.
  int clicks = 0;
  double last_s = 0;
  std::set<std::string> phases;
  const Played r = play(task, feed, 22.0, [&](double t, double s) {
    // A click whenever a turn phase (7.2–9.2 script time) has just been played to its end.
    if (last_s < 9.25 && s >= 9.25) ++clicks;
    last_s = s;
    phases.insert(task.phase(t));
    return cube_at(p, script_lift(p, s), clicks);
  });
  const TaskProgress pr = task.progress();
  EXPECT_EQ(pr.turns_seen, 2);
  EXPECT_EQ(pr.retries_turn, 1);
  EXPECT_EQ(pr.attempts, 3);
  EXPECT_FALSE(pr.gave_up);
  EXPECT_LT(r.min_script_jump, -3.0);  // the regrasp-and-turn stretch was replayed
  EXPECT_GT(r.finished_at_s, p.duration + 3.0);
  EXPECT_LE(r.finished_at_s, p.deadline);
  EXPECT_LT(r.max_step_m, 0.0005);  // cross-faded: no jump in the fingertips
  // The phases name the turn being made: the first, then the first again, then the second.
  EXPECT_TRUE(phases.count("turn 1 (top layer)"));
  EXPECT_TRUE(phases.count("turn 1 (top layer), again"));
  EXPECT_TRUE(phases.count("turn 2 (top layer)"));
  for (const auto& name : phases) EXPECT_EQ(name.find("turn 3"), std::string::npos) << name;
}

/// How far a fingertip proxy centred at p_W stands clear of the axis-aligned cube centred at
/// c_W (half size `half`, proxy radius `radius`) [m]; negative: it would be inside.
double clearance(const Vec3& p_W, const Vec3& c_W, double half, double radius) {
  const Vec3 d = (p_W - c_W).cwiseAbs() - Vec3::Constant(half);
  const double outside = d.cwiseMax(0.0).norm();
  return (outside > 0 ? outside : d.maxCoeff()) - radius;
}

TEST(ClosedLoopUser, ARetriedSecondTurnTakesTheOpenHandAroundTheCubeNotThroughIt) {
  RubiksTask task({});
  core::Latest<CubePoseSample> feed;
  task.track(&feed);
  const RubiksTaskParams p = task.params();
  // The first turn clicks, the second does not: at the later check (9.9 s) the right hand is open
  // at the second turn's yaw, and the retry cross-fades it to where the regrasp starts (5.7 s),
  // open at the first turn's yaw, a quarter turn and more away about the cube's vertical axis.
  // Cut straight across, that path went through the top layer (the short, wide user's cube was
  // squeezed out of the hands and thrown off the table, 2026-11-26).
  double check_t = -1, min_clear = 1.0, s_prev = 0, max_step = 0;
  Vec3 cube_W = Vec3::Zero();
  std::array<Vec3, 8> g, g_prev;
  for (int k = 0; k <= 11000; ++k) {
    const double t = k * 1e-3, s = task.script_time(t);
    if (check_t < 0 && s < s_prev - 1.0) check_t = t;  // the jump back of the retry
    s_prev = s;
    const CubePoseSample c = cube_at(p, script_lift(p, s), s >= 5.3 ? 1 : 0);
    feed.publish(c);
    task.goals(t, g);
    cube_W = Vec3(c.p_W[0], c.p_W[1], c.p_W[2]);
    if (check_t >= 0 && t <= check_t + 0.8)
      for (int f = 4; f < 8; ++f) {
        min_clear = std::min(min_clear, clearance(g[f], cube_W, p.half, p.proxy_radius));
        max_step = std::max(max_step, (g[f] - g_prev[f]).norm());
      }
    g_prev = g;
  }
  ASSERT_GT(check_t, 9.8);
  ASSERT_LT(check_t, 10.0);
  std::printf("the right hand's fingertip proxies clear the cube by %.1f mm or more in the cross-fade\n", 1e3 * min_clear);
  EXPECT_EQ(task.progress().retries_turn, 1);
  EXPECT_GT(min_clear, 0.0) << "the right hand's open fingertips cut into the cube during the retry's cross-fade";
  // The cross-fade's target moves on (the hand turns back, 5.7–6.5 s), so that the swing passes
  // half a turn: it keeps its way round, and no goal jumps (measured: 0.3 mm per ms at most).
  std::printf("largest goal step in the cross-fade %.2f mm per ms\n", 1e3 * max_step);
  EXPECT_LT(max_step, 0.001);
}

// A cube that sinks in the holding hand while the other turns the layer: the user grips harder,
// the holding hand's goals going firm_squeeze deeper into their faces; a cube that stays put
// changes nothing.
TEST(ClosedLoopUser, ACubeSinkingInTheHoldingHandMakesItGripHarder) {
  struct Run {
    std::array<Vec3, 8> goals_at_8_8;
    double max_step_m = 0;
    TaskProgress progress;
  };
  auto run = [](double sink_m) {
    RubiksTask task({});
    core::Latest<CubePoseSample> feed;
    task.track(&feed);
    const RubiksTaskParams p = task.params();
    Run r;
    std::array<Vec3, 8> g, prev;
    for (int k = 0; k <= 8800; ++k) {
      const double t = k * 1e-3, s = task.script_time(t);
      // Turn 2 (7.2–9.2 s): the cube sinks by sink_m between 7.8 and 8.3 s.
      const double sunk = sink_m * std::clamp((s - 7.8) / 0.5, 0.0, 1.0);
      feed.publish(cube_at(p, script_lift(p, s) - sunk, (s >= 5.3) + (s >= 9.5)));
      task.goals(t, g);
      if (k > 0)
        for (int f = 0; f < 8; ++f) r.max_step_m = std::max(r.max_step_m, (g[f] - prev[f]).norm());
      prev = g;
    }
    r.goals_at_8_8 = g;
    r.progress = task.progress();
    return r;
  };
  const Run steady = run(0.0), sinking = run(0.004);
  const RubiksTaskParams p{};
  EXPECT_LT(steady.progress.firm_since_s, 0.0);
  EXPECT_GT(sinking.progress.firm_since_s, 7.8);  // once the cube is 2 mm (sink) lower
  EXPECT_LT(sinking.progress.firm_since_s, 8.1);
  // Each left fingertip goes deeper along its face's inward normal: the thumb +y (its face is the
  // front), the fingers −y (the back); the right hand unchanged.
  const std::array<Vec3, 4> inward{Vec3::UnitY(), -Vec3::UnitY(), -Vec3::UnitY(), -Vec3::UnitY()};
  for (int f = 0; f < 4; ++f)
    EXPECT_LT((sinking.goals_at_8_8[f] - steady.goals_at_8_8[f] - p.firm_squeeze * inward[f]).norm(), 1e-4) << f;
  for (int f = 4; f < 8; ++f) EXPECT_LT((sinking.goals_at_8_8[f] - steady.goals_at_8_8[f]).norm(), 1e-9) << f;
  EXPECT_LT(sinking.max_step_m, 0.0005);  // ramped in: no jump
}

TEST(ClosedLoopUser, RetriesStopAtTheDeadline) {
  RubiksTaskParams tp;
  tp.deadline = 14.0;  // room for the script and no retry
  RubiksTask task(tp);
  core::Latest<CubePoseSample> feed;
  task.track(&feed);
  const Played r = play(task, feed, 15.0, [&](double, double s) { return cube_at(tp, script_lift(tp, s), 0); });
  const TaskProgress pr = task.progress();
  EXPECT_EQ(pr.turns_seen, 0);
  EXPECT_TRUE(pr.gave_up);
  EXPECT_LE(r.finished_at_s, tp.deadline);
  EXPECT_GT(r.finished_at_s, 0);
}

TEST(ClosedLoopUser, ASlippedGraspIsMadeAgainWhereTheCubeLies) {
  RubiksTask task({});
  core::Latest<CubePoseSample> feed;
  task.track(&feed);
  const RubiksTaskParams p = task.params();
  // At 4 s the cube drops out of the hands to the table, 1 cm to the side; then it is held
  // where the script carries it from there.
  bool dropped = false;
  double regrasp_t = -1;
  std::string phase_after;
  const Played r = play(task, feed, 16.0, [&](double t, double s) {
    if (t >= 4.0 && !dropped && task.progress().retries_grasp == 0) {
      CubePoseSample c = cube_at(p, 0.0, 0);
      c.p_W[0] += 0.01;
      return c;
    }
    if (task.progress().retries_grasp > 0 && regrasp_t < 0) {
      regrasp_t = t;
      phase_after = task.phase(t + 0.05);
      dropped = true;
    }
    CubePoseSample c = cube_at(p, script_lift(p, s), (s >= 5.3) + (s >= 9.5));
    if (dropped) c.p_W[0] += 0.01;
    return c;
  });
  const TaskProgress pr = task.progress();
  EXPECT_EQ(pr.retries_grasp, 1);
  EXPECT_GT(regrasp_t, 4.25);  // a drop must last 0.3 s
  EXPECT_LT(regrasp_t, 4.6);
  EXPECT_EQ(phase_after, "approach the cube again");
  EXPECT_EQ(pr.turns_seen, 2);
  EXPECT_LT(r.max_step_m, 0.0015);  // the grasp frames move with the cube: a small step
  // The grasp follows the cube: after the regrasp the right thumb's goal is 1 cm further in x.
  std::array<Vec3, 8> g0, g1;
  RubiksTask ref({});
  ref.goals(3.0, g0);
  task.goals(regrasp_t + (3.0 - 0.7), g1);  // script time 3.0 again (s = 0.7 at the regrasp)
  EXPECT_NEAR(g1[4].x() - g0[4].x(), 0.01, 2e-3);
}

/// The cube of a grasp that slips in the second turn: where the script carries it, the first turn
/// clicked at script time 5.3, until at 8.6 s it drops to the table.
CubePoseSample slips_in_the_second_turn(const RubiksTaskParams& p, double t, double s) {
  if (t >= 8.6) return cube_at(p, 0.0, 1);
  return cube_at(p, script_lift(p, s), s >= 5.3 ? 1 : 0);
}

// A grasp that slips in the second turn, with the first turn made: the regrasp needs room for the
// one turn left, not for the whole script (at most 0.8 + 5.0 + 0.6 + 2.1 s, not 12.1), so at 8.6 s it
// still fits before the deadline of 20 s; the regrasp's turn is the last, and the script goes on
// to set the cube down without a third.
TEST(ClosedLoopUser, AGraspSlippedInTheLastTurnIsMadeAgainForTheTurnLeft) {
  RubiksTask task({});
  core::Latest<CubePoseSample> feed;
  task.track(&feed);
  const RubiksTaskParams p = task.params();
  double regrasp_t = -1;
  int turns_at_regrasp_check = -1;
  const Played r = play(task, feed, 20.0, [&](double t, double s) {
    if (regrasp_t < 0 && task.progress().retries_grasp > 0) regrasp_t = t;
    if (regrasp_t < 0) return slips_in_the_second_turn(p, t, s);
    // Grasped again and turned: the turn clicks at script time 5.3 of the replay.
    const int turns = 1 + (t > regrasp_t + 1.0 && s >= 5.3 ? 1 : 0);
    if (turns_at_regrasp_check < 0 && t > regrasp_t + 1.0 && s >= 5.7) turns_at_regrasp_check = turns;
    return cube_at(p, script_lift(p, s), turns);
  });
  const TaskProgress pr = task.progress();
  EXPECT_EQ(pr.retries_grasp, 1);
  EXPECT_FALSE(pr.gave_up);
  EXPECT_GT(regrasp_t, 8.85);  // a drop must last 0.3 s
  EXPECT_LT(regrasp_t, 9.2);
  EXPECT_EQ(turns_at_regrasp_check, 2);
  EXPECT_EQ(pr.turns_seen, 2);
  EXPECT_EQ(pr.retries_turn, 0);
  // The replayed stretch 0.7–5.7, then the set-down and withdrawal 9.9–12.0.
  EXPECT_NEAR(r.finished_at_s, regrasp_t + 5.0 + 2.1, 0.05);
  EXPECT_LE(r.finished_at_s, p.deadline);
  EXPECT_LT(r.max_step_m, 0.0015);
}

// After a slip the hands letting go carry the cube up for a moment (the demo: 10–16 mm while they
// open again): the new grasp is made where the cube will lie, not where it was seen in the air, so
// the cube then held 10 mm up is not taken for another slip.
TEST(ClosedLoopUser, ACubeCarriedUpWhileTheHandsLetGoIsGraspedWhereItWillLie) {
  RubiksTask task({});
  core::Latest<CubePoseSample> feed;
  task.track(&feed);
  const RubiksTaskParams p = task.params();
  double regrasp_t = -1;
  const Played r = play(task, feed, 20.0, [&](double t, double s) {
    if (regrasp_t < 0 && task.progress().retries_grasp > 0) regrasp_t = t;
    if (regrasp_t < 0) return slips_in_the_second_turn(p, t, s);
    if (s < 1.0) return cube_at(p, 0.012, 1);  // carried up by the opening hands
    const int turns = 1 + (t > regrasp_t + 1.0 && s >= 5.3 ? 1 : 0);
    return cube_at(p, 0.5 * script_lift(p, s), turns);  // held lower than the script lifts it
  });
  const TaskProgress pr = task.progress();
  EXPECT_EQ(pr.retries_grasp, 1);
  EXPECT_FALSE(pr.gave_up);
  EXPECT_EQ(pr.turns_seen, 2);
  EXPECT_LT(r.max_step_m, 0.0015);
  // The grasp closes at the cube's resting height: the left thumb's goal at script time 1.5 of the
  // replay is where an untroubled run has it.
  std::array<Vec3, 8> g0, g1;
  RubiksTask ref({});
  ref.goals(1.5, g0);
  task.goals(regrasp_t + (1.5 - 0.7), g1);
  EXPECT_NEAR(g1[0].z(), g0[0].z(), 1e-3);
}

TEST(ClosedLoopUser, ACubeHeldLowerThanTheScriptLiftsItIsNoSlip) {
  RubiksTask task({});
  core::Latest<CubePoseSample> feed;
  task.track(&feed);
  const RubiksTaskParams p = task.params();
  // Compliant fingertips carry the cube at 40 % of the script's lift.
  play(task, feed, 14.0, [&](double, double s) {
    return cube_at(p, 0.4 * script_lift(p, s), (s >= 5.3) + (s >= 9.5));
  });
  EXPECT_EQ(task.progress().retries_grasp, 0);
  EXPECT_EQ(task.progress().turns_seen, 2);
}

TEST(ClosedLoopUser, ACubeGoneFromTheTableIsNotFollowed) {
  RubiksTask task({});
  core::Latest<CubePoseSample> feed;
  task.track(&feed);
  const RubiksTaskParams p = task.params();
  // At 4 s the cube falls off the table and keeps falling.
  const Played r = play(task, feed, 12.0, [&](double t, double s) {
    CubePoseSample c = cube_at(p, script_lift(p, s), 0);
    if (t >= 4.0) c.p_W[2] -= 0.5 * 9.81 * (t - 4.0) * (t - 4.0) + 0.1;
    return c;
  });
  EXPECT_TRUE(task.progress().gave_up);
  EXPECT_EQ(task.progress().retries_grasp, 0);
  EXPECT_LT(r.max_step_m, 0.0005);
  // No fingertip goal goes below the table's neighbourhood following the falling cube.
  for (double t = 4.0; t < 12.0; t += 0.05) {
    std::array<Vec3, 8> g;
    task.goals(t, g);
    for (const auto& x : g) EXPECT_GT(x.z(), p.p_W_cube.z() - 0.05) << t;
  }
}

TEST(ClosedLoopUser, OnePlannedTurnSkipsTheSecond) {
  RubiksTaskParams tp;
  tp.turns = 1;
  RubiksTask task(tp);
  core::Latest<CubePoseSample> feed;
  task.track(&feed);
  const Played r = play(task, feed, 14.0, [&](double, double s) { return cube_at(tp, script_lift(tp, s), s >= 5.3); });
  EXPECT_EQ(task.progress().turns_seen, 1);
  EXPECT_EQ(task.progress().attempts, 1);
  EXPECT_LT(r.finished_at_s, tp.duration - 3.0);  // the regrasp and second turn were skipped
  EXPECT_LT(r.max_step_m, 0.0005);
}

TEST(ClosedLoopUser, PhasesAreNamedFromTheScene) {
  RubiksTaskParams with_cube, without;
  without.has_cube = false;
  RubiksTask a(with_cube), b(without);
  EXPECT_EQ(a.phase(0.5), "approach");
  EXPECT_EQ(a.phase(4.0), "turn 1 (top layer)");
  EXPECT_EQ(a.phase(8.0), "turn 2 (top layer)");
  EXPECT_EQ(b.phase(0.5), "reach");
  EXPECT_EQ(b.phase(4.0), "twist the object");
  EXPECT_EQ(b.phase(8.0), "twist the object");
  EXPECT_EQ(b.phase(9.5), "let go, set it down");
  EXPECT_EQ(b.phase_kind(4.0), "twist");
  EXPECT_EQ(a.phase_kind(4.0), "turn");
  for (double t = 0; t < 13; t += 0.1) EXPECT_EQ(b.phase(t).find("layer"), std::string::npos) << t;
  EXPECT_EQ(b.progress().turns_planned, 0);
}

// A rigid object held by the left hand does not turn: without a cube the right hand only twists
// it (a third of a cube's turn), and the holding hand's fingertips stay where they are.
TEST(ClosedLoopUser, WithoutACubeTheRightHandOnlyTwistsTheHeldObject) {
  RubiksTaskParams with_cube, without;
  without.has_cube = false;
  RubiksTask a(with_cube), b(without);
  std::array<Vec3, 8> a0, a1, b0, b1;
  // Script time 3.0 to 5.0 s: lifted (the lift ends at 3.0 s), the right hand turning a cube's
  // layer from 0 to its full turn.
  a.goals(3.0, a0);
  a.goals(5.0, a1);
  b.goals(3.0, b0);
  b.goals(5.0, b1);
  // Each right fingertip's angle about the vertical through the grasp (the cube's centre).
  auto angle = [&](const Vec3& p0, const Vec3& p1) {
    const Vec3 c = with_cube.p_W_cube;
    const double a0z = std::atan2(p0.y() - c.y(), p0.x() - c.x()), a1z = std::atan2(p1.y() - c.y(), p1.x() - c.x());
    return std::remainder(a1z - a0z, 2 * units::kPi);
  };
  for (int f = 4; f < 8; ++f) {
    if (std::hypot(a0[f].x() - with_cube.p_W_cube.x(), a0[f].y() - with_cube.p_W_cube.y()) < 0.01) continue;  // on the axis
    const double turned = angle(a0[f], a1[f]), twisted = angle(b0[f], b1[f]);
    EXPECT_NEAR(std::abs(turned), with_cube.turn, 0.05) << "finger " << f;
    // Less than half the cube's turn (a quarter turn drags the fingertips against the object), but
    // a twist all the same: the right hand still changes its pose.
    EXPECT_LT(std::abs(twisted), 0.5 * std::abs(turned)) << "finger " << f;
    EXPECT_GT(std::abs(twisted), 0.2 * std::abs(turned)) << "finger " << f;
    EXPECT_GT(twisted * turned, 0.0) << "finger " << f;  // the same way round
  }
  for (int f = 0; f < 4; ++f) EXPECT_LT((b1[f] - b0[f]).norm(), 1e-6) << "left finger " << f;
}

// Fingers do not shrink with the object: on a box smaller than the cube the right hand's index and
// ring stay as far apart as on the cube (they were squeezed to 10 mm, past what the user's fingers
// adduct), and the left hand's fingers stay on the box's back face.
TEST(ClosedLoopUser, FingertipsOnASmallerObjectKeepTheCubesSpacing) {
  RubiksTaskParams cube, box;
  box.has_cube = false;
  box.half = 0.02;
  box.pitch = box.half * 2.0 / 3.0;  // as session::make_scripted_task sets it
  RubiksTask a(cube), b(box);
  std::array<Vec3, 8> ga, gb;
  a.goals(2.5, ga);  // grasped and lifting
  b.goals(2.5, gb);
  const double cube_spread = std::abs(ga[7].x() - ga[5].x());
  EXPECT_NEAR(cube_spread, 0.74 * cube.pitch, 1e-3);  // the cube's layout, unchanged
  EXPECT_NEAR(std::abs(gb[7].x() - gb[5].x()), cube_spread, 1e-3);
  const double lift = script_lift(box, 2.5);
  for (int f = 0; f < 4; ++f)
    EXPECT_LE(std::abs(gb[f].z() - box.p_W_cube.z() - lift), box.half - box.proxy_radius + 1e-6) << "left finger " << f;
}

TEST(ClosedLoopUser, PhaseKindsGroupTheScriptAndFollowItsJumps) {
  RubiksTask task({});
  const std::pair<double, const char*> expected[] = {{0.5, "approach"}, {1.5, "grasp"},   {2.5, "lift"},
                                                     {4.0, "turn"},     {6.0, "regrasp"}, {8.0, "turn"},
                                                     {10.0, "release"}, {11.5, "withdraw"}, {12.5, "done"}};
  for (const auto& [t, kind] : expected) EXPECT_EQ(task.phase_kind(t), kind) << t;
  // A retried second turn jumps back in the script: its frames are "regrasp" and "turn" again.
  core::Latest<CubePoseSample> feed;
  RubiksTask retry({});
  retry.track(&feed);
  const RubiksTaskParams p = retry.params();
  std::array<Vec3, 8> g;
  double jumped_at = -1, s_prev = 0;
  for (int k = 0; k <= 14000; ++k) {
    const double t = k * 1e-3, s = retry.script_time(t);
    if (jumped_at < 0 && s < s_prev - 1.0) jumped_at = t;
    s_prev = s;
    feed.publish(cube_at(p, script_lift(p, s), s >= 5.3 ? 1 : 0));
    retry.goals(t, g);
  }
  ASSERT_GT(jumped_at, 0);
  EXPECT_EQ(retry.phase_kind(jumped_at + 0.3), "regrasp");
  EXPECT_EQ(retry.phase_kind(jumped_at + 3.0), "turn");  // script time 8.7 s
}

}  // namespace
}  // namespace spidar::sim
