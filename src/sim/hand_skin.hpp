#pragma once
// The synthetic camera's hand geometry: smooth meshes built once per hand shape, posed per frame.
// Tapered bones (sphere-swept cones), a superellipsoid palm, a forearm and a bracelet, all
// derived from the same joints as the model's capsules but shaped differently.
#include <array>
#include <vector>

#include "spidar/core/scene_snapshot.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/sim/synthetic_camera.hpp"

namespace spidar::sim {

/// Finger ids of the non-digit parts in the shapes' `finger` field.
inline constexpr int kPalmPart = -1;
inline constexpr int kBraceletPart = 5;
inline constexpr int kForearmPart = 6;

/// A surface of revolution about z: sphere of radius r_a at z = 0, sphere of radius r_b at
/// z = length, joined by their common tangent cone. Shared vertices (smooth normals).
MeshData tapered_segment(double r_a, double r_b, double length, int slices = 16, int rings = 6);
/// |x/a|^(2/e) + |y/b|^(2/e) + |z/c|^(2/e) = 1 with e < 1 a rounded box of half extents (a, b, c).
MeshData rounded_box(const Vec3& half_extents, double exponent = 0.45, int slices = 24,
                     int stacks = 16);

/// Mesh indices of one hand's parts (into the camera's shared mesh list).
struct HandSkin {
  struct Bone {
    int mesh = -1;
    int finger = -1;
  };
  std::vector<Bone> bones;  ///< one per capsule of hand::hand_render_shapes, same order
  int palm_mesh = -1;
  int forearm_mesh = -1;
  double wrist_radius = 0.0;  ///< forearm radius at the wrist [m]
};

/// Builds one hand's meshes into `meshes`.
HandSkin build_hand_skin(const hand::HandModel& model, const SyntheticCameraParams& params,
                         std::vector<MeshData>* meshes);

/// Appends the hand posed by `q` (non-hand shapes with their own colours; hand/finger set so the
/// renderer's hand targets give ground truth).
void pose_hand_skin(const hand::HandModel& model, const HandSkin& skin, const hand::HandParams& q,
                    const SyntheticCameraParams& params, SceneSnapshot* scene);

}  // namespace spidar::sim
