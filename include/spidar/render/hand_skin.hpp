#pragma once
/// A hand's skin: smooth meshes built once per hand shape, posed per frame. Tapered bones
/// (sphere-swept cones, thicker at their proximal end), a superellipsoid palm, optionally a
/// forearm and a bracelet, all on the same joints as the model's capsules
/// (hand/render_geometry.hpp). The frame pipeline draws the fitted model hands with it, so that a
/// hand is compared with a hand, not with sticks. (The synthetic camera does not film it: the
/// simulated user has an anatomical hand of its own, sim/anatomical_hand.hpp.)
#include <array>
#include <vector>

#include "spidar/core/result.hpp"
#include "spidar/core/scene_snapshot.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/core/types.hpp"

namespace spidar::render {

/// The skin's shape and colours.
struct HandSkinParams {
  double taper = 0.12;                ///< bone radius: (1 + taper)·r proximal, (1 − taper)·r distal
  double palm_fullness = 1.2;         ///< palm thickness × this (vs the model's box)
  double forearm_length_m = 0.10;     ///< visible forearm beyond the wrist [m]; 0 = none
  /// How far the forearm's end reaches past the wrist into the hand, as a share of its radius
  /// (0..1]. A hemisphere (1) of the forearm's radius, about two thirds of the palm's half
  /// breadth, reaches 2.5–3 cm into the palm and stands out of it above and below, so that the
  /// pixels of the carpus were drawn (and labelled) forearm: 9 % of the real hands' pixels on the
  /// default user (tests/pipeline/registration_study --ceiling-scan).
  double forearm_cap_depth = 0.25;
  /// The palm's skin reaches back to the wrist (the skeleton's palm box starts at the carpus,
  /// about a centimetre from it): with the forearm's end flattened, the carpus is palm.
  bool palm_reaches_wrist = true;
  /// The palm's breadth at its wrist end, as a share of its breadth at the knuckles [0.5, 1]
  /// (it widens smoothly to full breadth halfway to the knuckles; 1: a box). A real palm is
  /// about 0.7–0.8 as broad at the wrist as across the knuckles; the box's square end added
  /// 5 % of the real hands' pixels at the wrist (registration_study --ceiling-scan).
  double palm_wrist_breadth = 0.8;
  /// The forearm's half breadth at the wrist, as a share of the palm's half breadth across the
  /// knuckles (0.4..1). Anthropometric tables give a wrist about 0.65–0.70 as broad as the hand.
  double forearm_breadth = 0.68;
  /// The forearm's half depth (back to front) as a share of its half breadth (0.4..1; 1: round).
  /// A wrist is about two thirds as deep as it is broad; a round forearm as broad as the wrist
  /// stood out of the palm above and below and hid the carpus (registration_study --ceiling-scan).
  double forearm_depth = 0.65;
  bool bracelet = true;               ///< a bracelet around the wrist
  double bracelet_width_m = 0.018;    ///< along the forearm [m]
  double bracelet_offset_m = 0.012;   ///< bracelet centre, from the wrist toward the elbow [m]
  std::array<float, 3> skin_rgb{0.88f, 0.66f, 0.54f};
  std::array<float, 3> bracelet_rgb{0.85f, 0.07f, 0.07f};
  /// Tessellation. The frame pipeline draws both hands every frame in software (llvmpipe), where
  /// the cost grows with the triangle count: 10 slices and 3 rings per end cap keep a bone's
  /// outline within 5 % of its radius (< 0.5 mm on a finger). With 14/8 for the palm, both hands
  /// have 6,216 triangles (without the bracelet) instead of 18,176 at 16/6 and 24/16, and their
  /// silhouettes agree with IoU 0.992–0.995 (tests/render/test_hand_skin.cpp); bench_pipeline's
  /// CPU time per frame fell by about a quarter.
  int bone_slices = 10;   ///< vertices around a bone, 6..64
  int bone_rings = 3;     ///< rings per hemispherical end of a bone, 2..32
  int palm_slices = 14;   ///< vertices around the palm, 8..64
  int palm_stacks = 8;    ///< rings from the palm's back to its front, 4..64
};

/// Error naming the first field out of its range.
Status validate(const HandSkinParams& params);

/// Finger ids of the non-digit parts in the shapes' `finger` field.
inline constexpr int kPalmPart = -1;
inline constexpr int kBraceletPart = 5;
inline constexpr int kForearmPart = 6;

/// A surface of revolution about z: sphere of radius r_a at z = 0, sphere of radius r_b at
/// z = length, joined by their common tangent cone. Shared vertices (smooth normals).
/// `cap_a_depth` flattens the end at z = 0: its cap reaches to z = −cap_a_depth·r_a (1: a
/// hemisphere; less: a shallow dome).
/// `cap_b_depth` the same for the end at z = length.
MeshData tapered_segment(double r_a, double r_b, double length, int slices = 16, int rings = 6,
                         double cap_a_depth = 1.0, double cap_b_depth = 1.0);

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
  int bracelet_mesh = -1;  ///< the band (HandSkinParams::bracelet), or −1
  double wrist_half_breadth = 0.0;  ///< forearm's half breadth at the wrist (along x_H) [m]
  double wrist_half_depth = 0.0;  ///< forearm's half depth at the wrist (along z_H) [m]
};

/// Builds one hand's meshes into `meshes`.
HandSkin build_hand_skin(const hand::HandModel& model, const HandSkinParams& params,
                         std::vector<MeshData>* meshes);

/// Appends the hand posed by `q` (non-hand shapes with their own colours; hand/finger set so the
/// renderer's hand targets give ground truth).
/// `toward_elbow_W` (unit, world; hand/forearm.hpp): the forearm and bracelet point along it,
/// bent at the wrist; null: in line with the hand (−y_H).
void pose_hand_skin(const hand::HandModel& model, const HandSkin& skin, const hand::HandParams& q,
                    const HandSkinParams& params, SceneSnapshot* scene, const Vec3* toward_elbow_W = nullptr);

}  // namespace spidar::render
