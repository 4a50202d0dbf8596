#pragma once
/// Virtual coupling between a device fingertip and its proxy in the virtual world: a
/// spring-damper. The proxy (a small sphere) is pulled toward the measured fingertip; the user
/// feels the opposite force. With physics in its own thread the servo loop evaluates the same
/// law against a local model of the proxy (its last position, held outside its contact planes).
#include <array>

#include "spidar/core/types.hpp"

namespace spidar::physics {

struct CouplingParams {
  double stiffness = 1000.0;  ///< [N/m] (Springhead's grasp application)
  double damping = 5.0;       ///< [N·s/m] on the relative velocity
  double max_force = 20.0;    ///< [N] cap on the coupling force
};

/// Force on the proxy [N]: k(p_F − p_P) + b(v_F − v_P), capped at max_force. The user feels
/// the negative of it.
Vec3 coupling_force(const CouplingParams& c, const Vec3& p_W_fingertip, const Vec3& v_W_fingertip,
                    const Vec3& p_W_proxy, const Vec3& v_W_proxy);

/// A half-space the proxy centre must stay in: n·p ≥ offset (n unit, world; offset [m]).
struct ContactPlane {
  Vec3 n_W = Vec3::UnitZ();
  double offset = 0.0;
};

inline constexpr int kMaxPlanes = 4;

/// What the servo loop needs of one proxy between physics steps.
struct ProxyState {
  Vec3 p_W = Vec3::Zero();     ///< proxy centre [m]
  Vec3 v_W = Vec3::Zero();     ///< proxy velocity [m/s]
  int plane_count = 0;
  std::array<ContactPlane, kMaxPlanes> planes{};
};

/// The local model: the proxy position at `dt` [s] after its physics step — moved with its
/// velocity and pushed back out of its contact planes — so the servo can render stiff contact
/// between physics updates.
Vec3 local_proxy_position(const ProxyState& proxy, double dt);

}  // namespace spidar::physics
