// Posing the anatomical hand: linear blend skinning on the CPU, straight into world coordinates.
#include <algorithm>
#include <cmath>

#include "spidar/hand/forearm.hpp"
#include "spidar/hand/kinematics.hpp"
#include "spidar/hand/rotation_vector.hpp"
#include "spidar/sim/anatomical_hand.hpp"

namespace spidar::sim {

SkinTransforms skin_transforms(const AnatomicalHand& hand, const hand::HandParams& params,
                               const Vec3* toward_elbow_W) {
  const HandBoneFrames now = hand_bone_frames(hand.model, params);
  // A = R_WH·M: right-hand H coordinates to world directions (M mirrors x for the left hand).
  const Mat3 R_WH = hand::rotation_from_vector(params.r_W_hand());
  Mat3 A = R_WH;
  if (hand.model.side == hand::Side::kLeft) A.col(0) = -A.col(0);
  const Vec3 p_W_wrist = params.p_W_wrist();
  SkinTransforms X;
  for (int b = 0; b < kHandBoneCount; ++b) {
    // X_W(B now) · X_H(B rest)⁻¹ applied to a rest point q: A·(R_now R_restᵀ (q − p_rest) + p_now).
    const Mat3 R = now.R_HB[b] * hand.rest.R_HB[b].transpose();
    Mat3 L = A * R;
    Vec3 t = p_W_wrist + A * (now.p_HB[b] - R * hand.rest.p_HB[b]);
    if (b == kForearmBone && toward_elbow_W) {  // the forearm turns about the wrist
      const Mat3 B = hand::wrist_bend(R_WH, *toward_elbow_W);
      L = B * L;
      t = p_W_wrist + B * (t - p_W_wrist);
    }
    X.L[b] = L.cast<float>();
    X.t[b] = t.cast<float>();
  }
  return X;
}

void pose_part(const SkinnedPart& part, const SkinTransforms& X, std::span<float> p_W,
               std::span<float> n_W) {
  const std::size_t n = std::min({part.p_H_rest.size(), p_W.size() / 3, n_W.size() / 3});
  for (std::size_t i = 0; i < n; ++i) {
    const BoneWeights& w = part.weights[i];
    const Eigen::Vector3f& q = part.p_H_rest[i];
    const Eigen::Vector3f& m = part.n_H_rest[i];
    Eigen::Vector3f p = Eigen::Vector3f::Zero(), nn = Eigen::Vector3f::Zero();
    for (int k = 0; k < 3; ++k) {
      const float wk = w.weight[static_cast<std::size_t>(k)];
      if (wk == 0.f) continue;
      const int b = w.bone[static_cast<std::size_t>(k)];
      p += wk * (X.L[b] * q + X.t[b]);
      nn += wk * (X.L[b] * m);
    }
    const float len = nn.norm();
    if (len > 1e-12f) nn /= len;
    for (int k = 0; k < 3; ++k) {
      p_W[3 * i + static_cast<std::size_t>(k)] = p[k];
      n_W[3 * i + static_cast<std::size_t>(k)] = nn[k];
    }
  }
}

std::vector<MeshData> part_meshes(const AnatomicalHand& hand) {
  std::vector<MeshData> meshes;
  for (const SkinnedPart& part : hand.parts) {
    MeshData m;
    m.name = part.name;
    m.faces = part.faces;
    for (std::size_t i = 0; i < part.p_H_rest.size(); ++i)
      for (int k = 0; k < 3; ++k) {
        m.vertices.push_back(part.p_H_rest[i][k]);
        m.normals.push_back(part.n_H_rest[i][k]);
      }
    meshes.push_back(std::move(m));
  }
  return meshes;
}

void pose_anatomical_hand(const AnatomicalHand& hand, const hand::HandParams& params,
                          std::span<MeshData> meshes, const Vec3* toward_elbow_W) {
  const SkinTransforms X = skin_transforms(hand, params, toward_elbow_W);
  for (std::size_t i = 0; i < hand.parts.size() && i < meshes.size(); ++i) {
    pose_part(hand.parts[i], X, meshes[i].vertices, meshes[i].normals);
    ++meshes[i].version;
  }
}

}  // namespace spidar::sim
