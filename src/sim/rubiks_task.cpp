#include "spidar/core/units.hpp"
#include "spidar/sim/rubiks_task.hpp"
#include "smooth_ramp.hpp"

#include <Eigen/Geometry>

#include "spidar/hand/kinematics.hpp"
#include <algorithm>
#include <cmath>

namespace spidar::sim {
namespace {

Mat3 rot_z(double a) { return Eigen::AngleAxisd(a, Vec3::UnitZ()).toRotationMatrix(); }

struct Contacts {
  std::array<Vec3, 4> left, right;
};

/// The pitch that spaces the fingertips of one hand across each other (the right hand's index and
/// ring either side of the middle, the left hand's fingers stacked down the back face), the
/// farthest at `extent` pitches from the centre: the cube's layer pitch. A smaller object keeps the
/// cube's spacing as far as its face allows (the proxy sphere's centre within half − r of its
/// centre): the fingers do not shrink with the object, and fingertips squeezed closer than the
/// user's fingers can adduct pulled the size estimate's width to its bound.
double spread(const RubiksTaskParams& p, double extent) {
  if (p.has_cube) return p.pitch;
  const double cube = RubiksTaskParams{}.pitch;
  return std::max(p.pitch, std::min(cube, (p.half - p.proxy_radius) / extent));
}

/// Grasp contacts in the cube frame (world axes at the start), thumb, index, middle, ring.
Contacts contacts(const RubiksTaskParams& p) {
  const double face = p.half + p.proxy_radius - p.squeeze;
  const double hold = p.half + p.proxy_radius - p.hold_squeeze;
  const double a = p.pitch;
  Contacts c;
  // Each hand's pushes balance layer by layer, so that a grasp twists no layer of the cube: the
  // thumb presses at the mean position of the fingers opposite it, and every contact lies in the
  // middle vertical slice, close to the plane x = 0, where no pull along a face twists the L or
  // R layer and no push across a face twists U, D, F or B much.
  // Left hand on the two lower layers, from the left: thumb in front (−y), fingers behind (+y),
  // stacked down the back face. Three of the four press on the middle layer, so that it is the
  // middle layer that holds against the turning hand: the bottom layer then feels a third of the
  // holding torque and the top layer's twist clearly stands out (held by the bottom layer alone,
  // a top-layer turn and a bottom-layer turn would be the same twist).
  const double az = spread(p, 0.8), ax = spread(p, 0.37);
  c.left = {Vec3(-0.26 * a, -hold, -0.47 * az), Vec3(-0.2 * a, hold, -0.15 * az),
            Vec3(-0.26 * a, hold, -0.45 * az), Vec3(-0.32 * a, hold, -0.8 * az)};
  // With ring_on_side, on a cube the left ring finger presses on the left face instead, curled
  // less than the others, on the middle layer toward its back edge: 0.6 pitch behind the face's
  // centre, where the users ±10 % reach it within their active ranges (at 0.3 pitch the short,
  // wide user's ring went into its passive range). The device gives each hand two units that pull
  // toward the back and two toward the front (configs/spidar8.yaml), so a third finger on the
  // back face (the ring's unit pulls toward the front-top) displays almost nothing there. Every
  // unit of the left hand pulls toward −x, so the left face is one the ring's strings can push it
  // back from. Through the device in lockstep, with the cube turned −0.3 … 0.45 rad or moved 5 cm,
  // this grasp turned the layer twice at 8 of 8 placements, the back-face one at 3 of 8
  // (docs/measurements.md, "The cube elsewhere on the table"; test PlacedCubeThroughTheDevice).
  // Another object keeps the back-face layout: its extent across x is not known (the pinch is
  // along y).
  if (p.has_cube && p.ring_on_side) c.left[3] = Vec3(-hold, 0.6 * a, -0.45 * az);
  // Right hand on the top layer, from above: thumb in front, index and ring behind either side
  // of the middle, which presses on the top. High on the layer: a fingertip on the middle layer
  // would drag it along.
  const double zr = 1.2 * a;
  c.right = {Vec3(0.0, -face, zr), Vec3(-0.37 * ax, face, zr),
             Vec3(0.0, 0.2 * a, p.half + p.proxy_radius - 0.6 * p.squeeze), Vec3(0.37 * ax, face, zr)};
  return c;
}

/// True for a contact on the top face; the others press on a side face. (Goals lie `squeeze`
/// inside the faces, so a side contact's |y| is less than half the cube: the face a contact
/// belongs to is told by its height, which only a top contact has above the top.)
bool on_top(const Vec3& c, double half) { return c.z() >= half - 1e-9; }

/// Outward normal of a contact's face, cube frame: the top, or the side face (front, back, left
/// or right) the contact lies deepest toward.
Vec3 face_normal(const Vec3& c, double half) {
  if (on_top(c, half)) return Vec3::UnitZ();
  if (std::abs(c.x()) > std::abs(c.y())) return Vec3(c.x() > 0 ? 1 : -1, 0, 0);
  return Vec3(0, c.y() > 0 ? 1 : -1, 0);
}

/// Where a contact's fingertip is with the hand open: out along the face normal, up a little.
Vec3 opened(const Vec3& c, double half) { return c + 0.025 * face_normal(c, half) + Vec3(0, 0, 0.01); }

// Nominal hand poses at the grasp, cube frame: wrist position [m], hand rotation, finger angles.
struct Nominal {
  Vec3 p_wrist;
  Mat3 R;
};
Nominal nominal_grasp(hand::Side side) {
  if (side == hand::Side::kRight) {
    // Over the top, fingers forward and a little down, wrist toward the user.
    return {Vec3(0.012, -0.105, 0.072), Eigen::AngleAxisd(-0.25, Vec3::UnitX()).toRotationMatrix()};
  }
  // From the left, palm toward +x (the cube), thumb up, fingers forward.
  return {Vec3(-0.070, -0.080, 0.0), Eigen::AngleAxisd(-1.45, Vec3::UnitY()).toRotationMatrix()};
}

/// The point a share w of the way from `from` to `to` [m, world] along an arc about the vertical
/// axis of grasp frame G (through p_WG along z_G): angle about the axis, distance from it and height
/// along it each blended linearly. A hand cross-fading between two yaws of the turn (a retry) then
/// goes around the cube, as the script's own turns do, and not across it: the straight chord
/// between two open fingertips a quarter turn apart cuts into the top layer. A fingertip that
/// swings about the axis by more than kSwingFrom also rises, by up to kSwingRise at mid-swing, so
/// it passes over the top layer's corners instead of brushing them; a holding hand, whose
/// fingertips keep their angle, is blended as before. `swing_rad`: how far the hand turns about
/// the axis between the two (the difference of the script's yaws, unwrapped): the arc takes the
/// way round nearest to it, so that a swing near half a turn, whose target moves on, never flips
/// to the other side of the cube.
Vec3 blend_about_axis(const Vec3& from, const Vec3& to, double w, const Vec3& p_WG, const Mat3& R_WG,
                      double swing_rad) {
  constexpr double kSwingFrom = 0.17, kSwingFull = 0.5;  // [rad] about 10° and 30°
  constexpr double kSwingRise = 0.015;                    // [m]
  const Vec3 a = from - p_WG, b = to - p_WG;
  const Vec3 x = R_WG.col(0), y = R_WG.col(1), z = R_WG.col(2);
  const double ra = std::hypot(a.dot(x), a.dot(y)), rb = std::hypot(b.dot(x), b.dot(y));
  constexpr double kNearAxis = 1e-4;  // [m] too close to the axis for an angle: straight
  if (ra < kNearAxis || rb < kNearAxis) return (1.0 - w) * from + w * to;
  const double phi_a = std::atan2(a.dot(y), a.dot(x));
  const double dphi =
      swing_rad + std::remainder(std::atan2(b.dot(y), b.dot(x)) - phi_a - swing_rad, 2.0 * units::kPi);
  const double phi = phi_a + w * dphi, r = (1.0 - w) * ra + w * rb;
  const double swing = std::clamp((std::abs(dphi) - kSwingFrom) / (kSwingFull - kSwingFrom), 0.0, 1.0);
  const double h = (1.0 - w) * a.dot(z) + w * b.dot(z) + swing * kSwingRise * std::sin(units::kPi * w);
  return p_WG + r * (std::cos(phi) * x + std::sin(phi) * y) + h * z;
}

/// A grasp frame G from its published position [m] and orientation (w, x, y, z).
Pose grasp_frame(const std::array<double, 3>& p_WG, const std::array<double, 4>& q_WG) {
  Pose X;
  X.p = Vec3(p_WG[0], p_WG[1], p_WG[2]);
  X.R = Quat(q_WG[0], q_WG[1], q_WG[2], q_WG[3]).normalized();
  return X;
}

}  // namespace

bool RubiksTask::looks_for_grasp(double t, hand::Side side) {
  // While a hand approaches for a grasp (open, before closing), never while it holds the cube or
  // lets go of it: an open hand that follows the cube could push it along without end.
  if (t < 1.0) return true;
  return side == hand::Side::kRight && t >= 5.7 && t < 6.5;
}

double RubiksTask::closeness(double t, hand::Side side) {
  if (side == hand::Side::kLeft) return ramp(t, 1.0, 2.0) - ramp(t, 9.9, 10.6);
  return ramp(t, 1.0, 2.0) - ramp(t, 5.0, 5.7) + ramp(t, 6.5, 7.2) - ramp(t, 9.2, 9.9);
}

RubiksTask::HandState RubiksTask::state(double t, hand::Side side, int /*finger*/) const {
  HandState s;
  // Held up through both turns (on the table, its friction on the bottom layer and the holding
  // hand's on the lower layers twist the cube about as much as the turning hand: no layer stands
  // out to break away); set down while the right hand lets go after turn 2, to just above the
  // table (the cube may have slipped a little in the hand).
  s.lift = p_.lift * (ramp(t, 2.0, 3.0) - 0.75 * ramp(t, 9.2, 9.9));
  // A cube's top layer turns; any other object is rigid and held by the left hand, and the right
  // hand only twists it, by kRigidTwistShare of the turn (rubiks_task.hpp).
  if (side == hand::Side::kRight) {
    const double share = p_.has_cube ? 1.0 : kRigidTwistShare;
    s.yaw = share * p_.turn * (ramp(t, 3.0, 5.0) - ramp(t, 5.7, 6.5) + ramp(t, 7.2, 9.2) - ramp(t, 10.6, 11.3));
  }
  return s;
}

RubiksTask::RubiksTask(RubiksTaskParams p) : p_(p) {
  for (int h = 0; h < 2; ++h) {
    frames_.p_W[h] = {p_.p_W_cube.x(), p_.p_W_cube.y(), p_.p_W_cube.z()};
    frames_.q_WG[h] = {1, 0, 0, 0};
    frames_.lift[h] = 0;
  }
  published_.publish(frames_);
  plan_.progress.turns_planned = p_.has_cube ? std::max(1, p_.turns) : 0;
  plan_.progress.attempts = p_.has_cube ? 1 : 0;
  published_plan_.publish(plan_);
}

void RubiksTask::goals(double t_run, std::span<Vec3> goal) {
  const std::optional<CubePoseSample> cube = cube_ != nullptr ? cube_->read() : std::nullopt;
  update_plan(t_run, cube);
  const double t = plan_.schedule.script_time(t_run);  // script time from here on
  if (cube_ != nullptr) {
    if (const auto& c = cube) {
      // The cube's orientation with its yaw reduced to (−45°, 45°] by its 90° symmetry.
      const Quat q(c->q_WC[0], c->q_WC[1], c->q_WC[2], c->q_WC[3]);
      const Mat3 R = q.normalized().toRotationMatrix();
      const double yaw = std::atan2(R(1, 0), R(0, 0));
      const double k = std::round(yaw / (units::kPi / 2));
      const Quat g(R * rot_z(-k * units::kPi / 2));
      for (int h = 0; h < 2; ++h) {
        const auto side = h == 0 ? hand::Side::kLeft : hand::Side::kRight;
        if (!looks_for_grasp(t, side)) continue;  // holding on or leaving: keep the frame
        if (!within_reach(*c)) continue;         // gone from the scene: never follow it away
        frames_.p_W[h] = c->p_W;
        // Approaching for a grasp of the cube on the table (s < 1): a cube seen above where it
        // rests is still carried by hands letting go of a slipped grasp, or falling; it will lie
        // at its resting height, which the grasp (and the slip check's reference) then takes.
        if (t < 1.0) frames_.p_W[h][2] = std::min(c->p_W[2], p_.p_W_cube.z());
        frames_.q_WG[h] = {g.w(), g.x(), g.y(), g.z()};
        frames_.lift[h] = state(t, side, 0).lift;
      }
      published_.publish(frames_);
    }
  }
  scheduled_goals(plan_, t_run, frames_, goal, true);
  // No faster than a hand moves (max_goal_speed); from the start, or a clock that went back (a
  // new run), wherever the script is.
  const bool limit = p_.shaped_fingers && prev_goal_t_ >= 0 && t_run >= prev_goal_t_;
  const double step = p_.max_goal_speed * (t_run - prev_goal_t_);
  for (std::size_t f = 0; f < goal.size() && f < prev_goal_.size(); ++f) {
    if (limit) {
      const Vec3 d = goal[f] - prev_goal_[f];
      if (d.norm() > step) goal[f] = prev_goal_[f] + d * (step / d.norm());
    }
    prev_goal_[f] = goal[f];
  }
  prev_goal_t_ = t_run;
  // The holds at the present script time (during a cross-fade, those of where it is going): the
  // nearest fitted sample, turned with its hand's grasp frame and yaw.
  for (int h = 0; h < 2; ++h) {
    const auto& table = fitted_hold_[h];
    if (table.empty()) continue;
    const auto [k, w] = fit_sample(t, table.size());
    const auto& local = table[w < 0.5 ? k : k + 1];
    const Quat q_WG(frames_.q_WG[h][0], frames_.q_WG[h][1], frames_.q_WG[h][2], frames_.q_WG[h][3]);
    const Mat3 R_WG =
        q_WG.toRotationMatrix() * rot_z(state(t, h == 0 ? hand::Side::kLeft : hand::Side::kRight, 0).yaw);
    for (int f = 0; f < 4; ++f)
      holds_[static_cast<std::size_t>(4 * h + f)] = {R_WG * local[f].R_WE, local[f].scale};
  }
}

bool RubiksTask::holds(std::span<device::FingertipHold> hold) {
  if (fitted_hold_[0].empty() || fitted_hold_[1].empty()) return false;
  for (std::size_t f = 0; f < hold.size() && f < holds_.size(); ++f) hold[f] = holds_[f];
  return true;
}

void RubiksTask::scheduled_goals(const Plan& plan, double t_run, const GraspFrames& fr,
                                 std::span<Vec3> goal, bool squeeze) const {
  const ScriptSegment& seg = plan.schedule.at(t_run);
  // The holding hand gripping harder (update_plan), ramped in over 0.2 s.
  const double since = plan.progress.firm_since_s;
  const double firm = squeeze && since >= 0 ? p_.firm_squeeze * ramp(t_run, since, since + 0.2) : 0.0;
  goals_at(plan.schedule.script_time(t_run), fr, goal, squeeze, firm);
  blend_goals(plan, seg, t_run, fr, goal, squeeze, firm);
}

void RubiksTask::blend_goals(const Plan& plan, const ScriptSegment& seg, double t_run, const GraspFrames& fr,
                             std::span<Vec3> goal, bool squeeze, double firm_m) const {
  const double w = blend_weight(seg, t_run);
  if (w >= 1.0) return;
  std::array<Vec3, 8> from;
  const bool newest = &seg == &plan.schedule.newest();
  goals_at(seg.s_from_s, newest ? plan.from_frames : fr, from, squeeze, firm_m);
  const double s_to = plan.schedule.script_time(t_run);
  for (std::size_t f = 0; f < goal.size() && f < from.size(); ++f)
    goal[f] = around_cube(f >= 4 ? hand::Side::kRight : hand::Side::kLeft, seg.s_from_s, s_to, fr, from[f], goal[f], w);
}

Vec3 RubiksTask::around_cube(hand::Side side, double s_from, double s_to, const GraspFrames& fr, const Vec3& from,
                             const Vec3& to, double w) const {
  const int h = side == hand::Side::kRight ? 1 : 0;
  const Pose G = grasp_frame(fr.p_W[h], fr.q_WG[h]);
  const double swing = state(s_to, side, 0).yaw - state(s_from, side, 0).yaw;
  return blend_about_axis(from, to, w, G.p, G.R.toRotationMatrix(), swing);
}

Vec3 RubiksTask::contact_normal(int f) const {
  const Contacts c = contacts(p_);
  return face_normal(f >= 4 ? c.right[f - 4] : c.left[f], p_.half);
}

Vec3 RubiksTask::squeeze_path(double t, int f) const {
  const Contacts c = contacts(p_);
  const bool right = f >= 4;
  const Vec3& contact = right ? c.right[f - 4] : c.left[f];
  const Vec3 n = face_normal(contact, p_.half);
  // How far the goal lies inside the face: the contact's depth below the touching position
  // (fingertip centre one proxy radius off the face).
  const double depth = (p_.half + p_.proxy_radius) - contact.dot(n);
  return -depth * closeness(t, right ? hand::Side::kRight : hand::Side::kLeft) * n;
}

Vec3 RubiksTask::script_path(double t, int f) const {
  const Contacts c = contacts(p_);
  const double approach = ramp(t, 0.0, 1.0);
  const double withdraw = ramp(t, 11.3, 12.0);
  const bool right = f >= 4;
  const Vec3& contact = right ? c.right[f - 4] : c.left[f];
  const Vec3 open = opened(contact, p_.half);
  // Where the hand starts and ends: the open hand moved as a whole toward its own side and up
  // (not toward the user, where the camera is). Both ends of the approach lie outside the faces'
  // planes (the offset toward the user is less than the opening), so the straight path between
  // them never crosses the cube.
  const Vec3 away = p_.withdraw * (right ? Vec3(0.75, 0.1, 0.35) : Vec3(-0.75, 0.1, 0.3));
  const Vec3 far = open + away;
  Vec3 p = far + (open - far) * approach + (far - open) * withdraw;
  p += (contact - open) * closeness(t, right ? hand::Side::kRight : hand::Side::kLeft);
  return p;
}

Vec3 RubiksTask::path(double t, int f) const {
  if (fitted_[f >= 4 ? 1 : 0].empty()) return script_path(t, f);
  return fitted_touch(t, f) + pressing(t, f);  // the fitted touching positions, pressed in
}

RubiksTask::FitSample RubiksTask::fit_sample(double t, std::size_t n) const {
  const double x = std::clamp(t / fit_dt_, 0.0, static_cast<double>(n - 1));
  const auto k = std::min(static_cast<std::size_t>(x), n - 2);
  return {k, x - static_cast<double>(k)};
}

Vec3 RubiksTask::fitted_touch(double t, int f) const {
  const auto& table = fitted_[f >= 4 ? 1 : 0];
  const auto [k, w] = fit_sample(t, table.size());
  return (1.0 - w) * table[k][f % 4] + w * table[k + 1][f % 4];
}

Vec3 RubiksTask::pressing(double t, int f) const {
  const Vec3 s = squeeze_path(t, f);
  const auto& table = fitted_hold_[f >= 4 ? 1 : 0];
  if (table.empty() || s.isZero()) return s;
  // The finger's compliance relative to its softest direction, R·diag(1/scale)·Rᵀ, between the
  // neighbouring fitted samples.
  auto compliance = [&](std::size_t k) {
    const device::FingertipHold& h = table[k][f % 4];
    return Mat3(h.R_WE * h.scale.cwiseInverse().asDiagonal() * h.R_WE.transpose());
  };
  const auto [k, w] = fit_sample(t, table.size());
  return ((1.0 - w) * compliance(k) + w * compliance(k + 1)) * s;
}

void RubiksTask::touch_points(double t_run, std::span<Vec3> p_W) const {
  scheduled_goals(read_plan(), t_run, read_frames(), p_W, false);
}

void RubiksTask::goals_at(double t, const GraspFrames& fr, std::span<Vec3> goal, bool squeeze,
                          double firm_m) const {
  for (int f = 0; f < 8 && f < static_cast<int>(goal.size()); ++f) {
    const bool right = f >= 4;
    const auto side = right ? hand::Side::kRight : hand::Side::kLeft;
    const HandState s = state(t, side, f);
    const int h = right ? 1 : 0;
    const Quat q_WG(fr.q_WG[h][0], fr.q_WG[h][1], fr.q_WG[h][2], fr.q_WG[h][3]);
    const Vec3 p_WG(fr.p_W[h][0], fr.p_W[h][1], fr.p_W[h][2]);
    const Vec3 p = squeeze ? path(t, f) : Vec3(path(t, f) - pressing(t, f));
    goal[f] = p_WG + q_WG * (rot_z(s.yaw) * p) + Vec3(0, 0, s.lift - fr.lift[h]);
    // The holding hand's firmer grip: deeper along its faces' inward normals, as far as it is closed.
    if (!right && firm_m > 0) goal[f] -= firm_m * closeness(t, side) * (q_WG * contact_normal(f));
  }
}

hand::HandParams RubiksTask::nominal_local(double t, hand::Side side) const {
  const auto& table = fitted_q_[side == hand::Side::kRight ? 1 : 0];
  if (table.empty()) return script_nominal_local(t, side);
  const auto [k, w] = fit_sample(t, table.size());
  hand::HandParams q = table[k];
  q.q = (1.0 - w) * table[k].q + w * table[k + 1].q;  // neighbours 10 ms apart: small steps
  return q;
}

hand::HandParams RubiksTask::script_nominal_local(double t, hand::Side side) const {
  const bool right = side == hand::Side::kRight;
  const Contacts c = contacts(p_);
  const auto& cs = right ? c.right : c.left;
  // The wrist follows the fingertips' mean displacement from the grasp (the script's path: the
  // nominal pose does not depend on the hands it was fitted to).
  Vec3 shift = Vec3::Zero();
  for (int f = 0; f < 4; ++f) shift += (script_path(t, (right ? 4 : 0) + f) - cs[f]) / 4.0;
  const Nominal n = nominal_grasp(side);
  hand::HandParams q;
  const Eigen::AngleAxisd aa(n.R);
  q.set_wrist(n.p_wrist + shift, aa.angle() * aa.axis());
  // A relaxed grip: more flexion as the hand closes.
  const double k = 0.3 + 0.7 * closeness(t, side);
  q[hand::kThumbCmcFlexion] = 0.2 * k;
  q[hand::kThumbCmcAbduction] = 0.3 + 0.5 * k;
  q[hand::kThumbIp] = 0.2 + 0.3 * k;
  for (int p : {hand::kIndexMcpFlexion, hand::kMiddleMcpFlexion, hand::kRingMcpFlexion}) q[p] = 0.2 + 0.5 * k;
  for (int p : {hand::kIndexDip, hand::kMiddleDip, hand::kRingDip}) q[p] = 0.2 + 0.5 * k;
  return q;
}

hand::HandParams RubiksTask::nominal(double t_run, hand::Side side) const {
  const Plan plan = read_plan();
  const GraspFrames fr = read_frames();
  const ScriptSegment& seg = plan.schedule.at(t_run);
  hand::HandParams q = nominal_at(plan.schedule.script_time(t_run), side, fr);
  const double w = blend_weight(seg, t_run);
  if (w < 1.0) {  // neighbouring poses of one hand: a linear blend of the parameters is smooth
    const bool newest = &seg == &plan.schedule.newest();
    const hand::HandParams from = nominal_at(seg.s_from_s, side, newest ? plan.from_frames : fr);
    const Vec3 p_W_wrist = q.p_W_wrist();
    q.q = (1.0 - w) * from.q + w * q.q;
    // The wrist around the cube with the fingertips (scheduled_goals), not across it.
    q.set_wrist(around_cube(side, seg.s_from_s, plan.schedule.script_time(t_run), fr, from.p_W_wrist(), p_W_wrist, w),
                q.r_W_hand());
  }
  return q;
}

hand::HandParams RubiksTask::nominal_at(double t, hand::Side side, const GraspFrames& fr) const {
  const int h = side == hand::Side::kRight ? 1 : 0;
  const Quat qg(fr.q_WG[h][0], fr.q_WG[h][1], fr.q_WG[h][2], fr.q_WG[h][3]);
  const Vec3 p_WG(fr.p_W[h][0], fr.p_W[h][1], fr.p_W[h][2]);
  const HandState s = state(t, side, 0);
  const Vec3 up(0, 0, s.lift - fr.lift[h]);
  const Mat3 R = qg.toRotationMatrix() * rot_z(s.yaw);  // the grasp frame, turned
  hand::HandParams q = nominal_local(t, side);
  const Eigen::AngleAxisd aa(R * hand::hand_pose(q).R);
  q.set_wrist(p_WG + R * q.p_W_wrist() + up, aa.angle() * aa.axis());
  return q;
}

}  // namespace spidar::sim
