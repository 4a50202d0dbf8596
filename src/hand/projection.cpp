#include "spidar/hand/projection.hpp"

namespace spidar::hand {
namespace {

template <std::size_t N, typename J3, typename J2>
void project_points(const PointProjection& camera, const std::array<Vec3, N>& p_W, const J3& J_3d,
                    std::array<Vec2, N>* uv, J2* J_uv) {
  for (std::size_t i = 0; i < N; ++i) {
    const int row = static_cast<int>(i);
    if (uv) (*uv)[i] = camera.project(p_W[i]);
    if (J_uv) {
      J_uv->template middleRows<2>(2 * row).noalias() =
          camera.jacobian(p_W[i]) * J_3d.template middleRows<3>(3 * row);
    }
  }
}

}  // namespace

void project_joints(const PointProjection& camera, const HandPoints& points,
                    const JointJacobian& J_joints, std::array<Vec2, kJointCount>* uv,
                    ProjectedJointJacobian* J_uv) {
  project_points(camera, points.p_W_joint, J_joints, uv, J_uv);
}

void project_fingertips(const PointProjection& camera, const HandPoints& points,
                        const FingertipJacobian& J_fingertips,
                        std::array<Vec2, kFingertipCount>* uv, ProjectedFingertipJacobian* J_uv) {
  project_points(camera, points.p_W_fingertip, J_fingertips, uv, J_uv);
}

void projected_joints(const HandModel& model, const HandParams& params,
                      const PointProjection& camera, std::array<Vec2, kJointCount>* uv,
                      ProjectedJointJacobian* J_uv) {
  HandPoints points;
  JointJacobian J;
  forward_kinematics(model, params, &points, nullptr, J_uv ? &J : nullptr);
  project_points(camera, points.p_W_joint, J, uv, J_uv);
}

}  // namespace spidar::hand
