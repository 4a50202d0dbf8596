#pragma once
/// The simulated user's real hand as the synthetic camera films it: an anatomical skin of its own,
/// deliberately independent of the registration model's skin (render/hand_skin.hpp), so that the
/// rig does not film the estimator's own geometry (the simulated world is not the model: it must
/// not be produced by the estimator it tests).
///
/// Shape (built once per hand from the user's skeleton, hand::HandModel at the rest pose):
///   - a palm with thickness (fuller on the palmar side), the thenar (thumb side) and hypothenar
///     (little-finger side) pads, the metacarpal pads under the knuckles, a shallow hollow in its
///     middle and the knuckles standing out on the back;
///   - digits that taper from base to tip, slimmer between the joints than at the knuckles,
///     fuller on the palmar side (finger pads), with rounded tips; the thumb's metacarpal carries
///     the thenar mass;
///   - webs between the fingers' bases and the wide first web between thumb and index;
///   - fingernails: thin shells on the distal segments' dorsal side (their own part and colour);
///   - a wrist and forearm (a flattened tube, widening toward the elbow) and a red bracelet around
///     it (their own parts).
/// Proportions are anthropometric fractions of the hand's length and breadth (joint breadths
/// like a PIP ≈ 0.24 × palm breadth), not the model's capsule radii.
///
/// Skinning: every vertex is bound with linear blend skinning to up to three bones
/// (sim/hand_bones.hpp): rigid to one bone away from the joints, blended smoothly across each
/// joint, the webs between the palm and their two digits. Posing computes, per bone,
/// X_W(B at pose) · X(B at rest)⁻¹ and blends; the left hand mirrors the right hand's numbers
/// in x_H (its triangles are wound the other way round so they still face outward in world).
///
/// Frames: rest positions are in H (right-hand numbers, hand_shape.hpp) [m]; posed ones in
/// world W [m].
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "spidar/core/result.hpp"
#include "spidar/core/scene_snapshot.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/sim/hand_bones.hpp"

namespace spidar::sim {

struct AnatomicalHandParams {
  double forearm_length_m = 0.10;    ///< forearm beyond the wrist [m]; 0 = none
  double bracelet_width_m = 0.018;   ///< along the forearm [m]; 0 = no bracelet
  double bracelet_offset_m = 0.012;  ///< bracelet centre, from the wrist toward the elbow [m]
  double bracelet_thickness_m = 0.002;  ///< how far the band stands off the skin [m]
  std::array<float, 3> skin_rgb{0.88f, 0.66f, 0.54f};
  std::array<float, 3> nail_rgb{0.94f, 0.80f, 0.78f};  ///< pinkish white
  std::array<float, 3> bracelet_rgb{0.85f, 0.07f, 0.07f};
  int digit_slices = 20;  ///< vertices around a digit (palm and forearm use more)
};

/// Error naming the bad field.
Status validate(const AnatomicalHandParams& params);

/// Up to three bones per vertex (hand_bones.hpp) with weights summing to 1 (unused: weight 0).
struct BoneWeights {
  std::array<std::uint8_t, 3> bone{};
  std::array<float, 3> weight{};
};

enum class HandPart { kPalm, kDigit, kWeb, kNail, kForearm, kBracelet };

/// One closed surface of the hand, drawn as one mesh.
struct SkinnedPart {
  std::string name;  ///< e.g. "index", "index_nail", "web_index_middle"
  HandPart kind = HandPart::kPalm;
  /// The renderer's part id (render::encode_hand_id's finger): the digit for digits and nails,
  /// render::kPalmPart for the palm and webs, kForearmPart, kBraceletPart.
  int finger = -1;
  std::array<float, 3> rgb{};
  std::vector<Eigen::Vector3f> p_H_rest;  ///< vertices at the rest pose, H [m]
  std::vector<Eigen::Vector3f> n_H_rest;  ///< unit outward normals at the rest pose, H
  std::vector<BoneWeights> weights;       ///< per vertex
  std::vector<int> faces;                 ///< 3 per triangle, counter-clockwise from outside (W)
};

struct AnatomicalHand {
  hand::HandModel model;   ///< the skeleton it is bound to
  HandBoneFrames rest;     ///< bone frames at the rest pose (all parameters 0)
  std::vector<SkinnedPart> parts;
  /// Per digit (thumb … little): the part and vertex of the fingertip's pole (the skin's most
  /// distal point, on the digit's axis just beyond the end of the distal bone).
  std::array<int, hand::kFingerCount> tip_part{};
  std::array<int, hand::kFingerCount> tip_vertex{};
};

/// Builds the hand of `model` (its side, shape and dimensions). Fails on invalid params.
Result<AnatomicalHand> build_anatomical_hand(const hand::HandModel& model,
                                             const AnatomicalHandParams& params = {});

/// Per bone, the map from rest H coordinates to world at a pose: p_W = L·p_H_rest + t (L includes
/// the left hand's mirror). Normals map with L too (it is orthogonal).
struct SkinTransforms {
  std::array<Eigen::Matrix3f, kHandBoneCount> L;
  std::array<Eigen::Vector3f, kHandBoneCount> t;
};
/// `toward_elbow_W` (unit, world; hand::forearm_direction): the forearm bone points along it,
/// bent at the wrist from the hand's axis (hand::wrist_bend); null: in line with the hand.
SkinTransforms skin_transforms(const AnatomicalHand& hand, const hand::HandParams& params,
                               const Vec3* toward_elbow_W = nullptr);

/// Writes part's posed vertices and unit normals into p_W and n_W (x y z per vertex, world),
/// which must hold 3 floats per vertex. Allocates nothing.
void pose_part(const SkinnedPart& part, const SkinTransforms& X, std::span<float> p_W,
               std::span<float> n_W);

/// A mesh for each part (name, faces, vertices and normals at the rest pose mapped by the
/// identity), to be posed in place by pose_anatomical_hand.
std::vector<MeshData> part_meshes(const AnatomicalHand& hand);

/// Poses every part of `hand` by `params` into meshes[i] (i = part index; made by part_meshes),
/// in world, and increments each mesh's version so a renderer uploads it again. Allocates nothing.
void pose_anatomical_hand(const AnatomicalHand& hand, const hand::HandParams& params,
                          std::span<MeshData> meshes, const Vec3* toward_elbow_W = nullptr);

}  // namespace spidar::sim
