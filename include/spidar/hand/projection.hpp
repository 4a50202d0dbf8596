#pragma once
/// Projected joint positions and their Jacobians (2D), through a camera the hand module does not
/// know: anything that projects a world point to pixels and gives the 2×3 Jacobian of that.
/// (vision::Camera will implement `PointProjection`; hand must not depend on vision.)
///
/// Chain rule per point: ∂uv/∂q = (∂uv/∂p_W)(p_W) · ∂p_W/∂q.
#include <array>
#include <functional>
#include <utility>

#include "spidar/hand/kinematics.hpp"

namespace spidar::hand {

using ProjectionJacobian = Eigen::Matrix<double, 2, 3>;

/// A projection of world points to the image [px].
class PointProjection {
 public:
  virtual ~PointProjection() = default;
  /// Pixel coordinates of a world point [px].
  virtual Vec2 project(const Vec3& p_W) const = 0;
  /// ∂(pixel)/∂p_W at p_W [px/m].
  virtual ProjectionJacobian jacobian(const Vec3& p_W) const = 0;
};

/// A PointProjection from two callables (tests, adapters).
class FunctionProjection final : public PointProjection {
 public:
  FunctionProjection(std::function<Vec2(const Vec3&)> project,
                     std::function<ProjectionJacobian(const Vec3&)> jacobian)
      : project_(std::move(project)), jacobian_(std::move(jacobian)) {}
  Vec2 project(const Vec3& p_W) const override { return project_(p_W); }
  ProjectionJacobian jacobian(const Vec3& p_W) const override { return jacobian_(p_W); }

 private:
  std::function<Vec2(const Vec3&)> project_;
  std::function<ProjectionJacobian(const Vec3&)> jacobian_;
};

/// ∂uv/∂q of the projected joints stacked: rows 2j, 2j+1 belong to joint j [px/m or px/rad].
using ProjectedJointJacobian = Eigen::Matrix<double, 2 * kJointCount, kParamCount>;
/// ∂uv/∂q of the projected fingertips stacked: rows 2i, 2i+1 belong to fingertip i.
using ProjectedFingertipJacobian = Eigen::Matrix<double, 2 * kFingertipCount, kParamCount>;

/// Projected joints [px] and, if `J_uv` is non-null, their Jacobian, from the 3D points and
/// joint Jacobian of forward_kinematics.
void project_joints(const PointProjection& camera, const HandPoints& points,
                    const JointJacobian& J_joints, std::array<Vec2, kJointCount>* uv,
                    ProjectedJointJacobian* J_uv);

/// The same for the four measured fingertips.
void project_fingertips(const PointProjection& camera, const HandPoints& points,
                        const FingertipJacobian& J_fingertips,
                        std::array<Vec2, kFingertipCount>* uv, ProjectedFingertipJacobian* J_uv);

/// Convenience: forward kinematics, then projected joints and their Jacobian.
void projected_joints(const HandModel& model, const HandParams& params,
                      const PointProjection& camera, std::array<Vec2, kJointCount>* uv,
                      ProjectedJointJacobian* J_uv);

}  // namespace spidar::hand
