#pragma once
/// A closed-loop script's clock: which script time a scripted user is at, at a given run time.
///
/// A script is a function of script time s (all of RubiksTask's motions are). Played open loop,
/// s equals the run time t. A user who watches the task jumps back in s to retry a step (a turn
/// that did not click, a grasp that slipped) or forward to skip one: a new segment then starts at
/// run time t0 from script time s0, and for `blend_s` seconds the user's motion cross-fades from
/// where the previous segment was left (script time s_from) to the new one, so that no jump in s
/// makes a jump in the fingertips.
///
/// Plain data (published between threads through core::Latest): the last kMaxSegments segments.
#include <array>
#include <cstdint>

namespace spidar::sim {

/// Why a segment started.
enum class SegmentKind : std::int32_t {
  kStart = 0,    ///< the run's start
  kNextTurn,     ///< on to the next planned turn
  kRetryTurn,    ///< a turn that did not click, tried again
  kRegrasp,      ///< the cube slipped from the grasp: approach and grasp it again
  kSkip,         ///< all planned turns done: on to setting the cube down
  kGiveUp,       ///< no time left for a retry: on to the end
};

/// One stretch of the script played at rate 1 from (t0_s, s0_s).
struct ScriptSegment {
  double t0_s = 0;      ///< run time the segment starts [s]
  double s0_s = 0;      ///< script time at t0 [s]
  double s_from_s = 0;  ///< script time the previous segment was left at (blend source) [s]
  double blend_s = 0;   ///< cross-fade duration from s_from [s] (0: none)
  SegmentKind kind = SegmentKind::kStart;
  std::int32_t attempt = 1;  ///< number of the turn attempt the segment's turn phase is
  /// The turn (1-based) the segment's first turn phase makes: a retry makes the same turn again.
  std::int32_t turn = 1;
};

struct ScriptSchedule {
  static constexpr int kMaxSegments = 8;
  std::array<ScriptSegment, kMaxSegments> segments{};  ///< oldest first
  std::int32_t count = 1;                               ///< segments in use (≥ 1)

  /// The segment that holds run time t (the newest with t0 ≤ t; the oldest kept for earlier t).
  const ScriptSegment& at(double t_s) const;
  /// Script time at run time t.
  double script_time(double t_s) const;
  /// Appends a segment (dropping the oldest when full).
  void start(const ScriptSegment& s);
  const ScriptSegment& newest() const { return segments[static_cast<std::size_t>(count - 1)]; }
};

/// Where a blended quantity stands at run time t in segment `seg`: 0 = all at s_from, 1 = all at
/// the segment's own script time (smooth in between; 1 without a blend).
double blend_weight(const ScriptSegment& seg, double t_s);

}  // namespace spidar::sim
