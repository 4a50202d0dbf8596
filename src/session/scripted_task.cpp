#include "spidar/session/scripted_task.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace spidar::session {

double pinch_half_extent(const Shape& s) {
  const Mat3 R = s.X_WS.R.toRotationMatrix();
  const Vec3 along_y = R.row(1).transpose();  // world y in the shape's frame
  switch (s.type) {
    case Shape::Type::kBox:
    case Shape::Type::kMesh:
      return along_y.cwiseAbs().dot(s.size.cwiseAbs());
    case Shape::Type::kSphere:
      return std::abs(s.size.x());
    case Shape::Type::kCapsule:
      return std::abs(along_y.z()) * std::abs(s.size.y()) + std::abs(s.size.x());
    case Shape::Type::kCylinder:
      return std::abs(along_y.z()) * std::abs(s.size.y()) +
             std::sqrt(std::max(0.0, 1.0 - along_y.z() * along_y.z())) * std::abs(s.size.x());
    case Shape::Type::kPlane:
      return 0.0;
  }
  return 0.0;
}

const Shape* nearest_object(const SceneSnapshot& scene) {
  double best = std::numeric_limits<double>::infinity();
  const Shape* target = nullptr;
  for (const Shape& s : scene.shapes) {
    if (s.body <= 0 || s.hand >= 0 || s.type == Shape::Type::kPlane) continue;
    const double d = s.X_WS.p.norm();
    if (d < best) {
      best = d;
      target = &s;
    }
  }
  return target;
}

Status reach_target(const SceneSnapshot& scene, sim::RubiksTaskParams* tp) {
  const Shape* target = nearest_object(scene);
  auto mm = [](double m) { return std::to_string(static_cast<long>(std::lround(1e3 * m))); };
  if (target == nullptr)
    return Error{"no object for the scripted user to reach for: the scene has no body of its own "
                 "besides the world's (add a <body> with a geom, e.g. a free box near the frame centre)"};
  const Vec3& p = target->X_WS.p;
  const std::string where = "the object nearest the frame centre, at (" + mm(p.x()) + ", " + mm(p.y()) + ", " +
                            mm(p.z()) + ") mm,";
  const double half = pinch_half_extent(*target);
  if (!(2 * half >= kMinPinchAcrossM && 2 * half <= kMaxPinchAcrossM))
    return Error{where + " is " + mm(2 * half) + " mm across the scripted user's pinch (thumb to fingers, along y); " +
                 "it holds objects " + mm(kMinPinchAcrossM) + " to " + mm(kMaxPinchAcrossM) + " mm across"};
  tp->p_W_cube = p;
  tp->half = half;
  tp->pitch = tp->half * 2.0 / 3.0;
  return Ok{};
}

Result<std::shared_ptr<sim::RubiksTask>> make_scripted_task(const physics::World& world,
                                                    const std::optional<physics::RubiksCube>& cube,
                                                    double proxy_radius,
                                                    const std::array<hand::HandModel, 2>& user,
                                                    Pose* X_cube0, const ScriptedUserOptions& options) {
  sim::RubiksTaskParams tp;
  tp.proxy_radius = proxy_radius;
  tp.has_cube = cube.has_value();
  tp.shaped_fingers = options.shaped_fingers;
  tp.ring_on_side = options.ring_on_side;
  if (options.deadline_s > 0) tp.deadline = options.deadline_s;
  *X_cube0 = Pose{};
  if (cube) {
    *X_cube0 = cube->core_pose();
    tp.p_W_cube = X_cube0->p;
  } else {
    SceneSnapshot s0;
    world.snapshot(s0, false);
    if (auto st = reach_target(s0, &tp); !st) return st.error();
    X_cube0->p = tp.p_W_cube;
  }
  auto task = std::make_shared<sim::RubiksTask>(tp);
  task->fit_to_hands(user, 0.01, std::array<double, 2>{options.fit_limit_margin_rad, 0.0});
  return std::shared_ptr<sim::RubiksTask>(std::move(task));
}

}  // namespace spidar::session
