#include "spidar/render/hand_skin.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <numbers>

#include "spidar/hand/forearm.hpp"
#include "spidar/hand/render_geometry.hpp"
#include "spidar/hand/rotation_vector.hpp"

namespace spidar::render {
namespace {

constexpr double kPi = std::numbers::pi;

void push(MeshData& m, const Vec3& p) {
  for (int k = 0; k < 3; ++k) m.vertices.push_back(static_cast<float>(p[k]));
}

/// Triangles of a (rows × cols) vertex grid wrapped in the second index; outward when the rows
/// run from −z to +z and the columns counter-clockwise about z.
void grid_faces(MeshData& m, int rows, int cols) {
  for (int i = 0; i + 1 < rows; ++i) {
    for (int j = 0; j < cols; ++j) {
      const int a = i * cols + j, b = i * cols + (j + 1) % cols;
      const int c = a + cols, d = b + cols;
      m.faces.insert(m.faces.end(), {a, b, d, a, d, c});
    }
  }
}

Pose along(const Vec3& p_W_origin, const Vec3& dir_W) {
  Pose X;
  X.p = p_W_origin;
  const double n = dir_W.norm();
  X.R = n > 1e-12 ? Quat::FromTwoVectors(Vec3::UnitZ(), dir_W / n) : Quat::Identity();
  return X;
}

/// The forearm's frame at `p_W_origin`: z toward the elbow (−y_H), x along x_H, y dorsal (z_H).
Pose forearm_frame(const Vec3& p_W_origin, const Mat3& R_WH) {
  Mat3 R;
  R.col(0) = R_WH.col(0);
  R.col(1) = R_WH.col(2);
  R.col(2) = -R_WH.col(1);
  Pose X;
  X.p = p_W_origin;
  X.R = Quat(R);
  return X;
}

std::array<float, 4> rgba(const std::array<float, 3>& c) { return {c[0], c[1], c[2], 1.f}; }

/// Scales `mesh`'s y by `sy` (an elliptic section about z from a round one). Positions only: the
/// renderer derives normals from the faces when a mesh has none.
void flatten_y(MeshData* mesh, double sy) {
  for (std::size_t k = 1; k < mesh->vertices.size(); k += 3) mesh->vertices[k] *= static_cast<float>(sy);
}

}  // namespace

MeshData tapered_segment(double r_a, double r_b, double length, int slices, int rings, double cap_a_depth,
                         double cap_b_depth) {
  MeshData m;
  m.name = "tapered_segment";
  // Elevation of the tangent circle: sin α = (r_a − r_b) / length.
  const double s = length > 1e-9 ? std::clamp((r_a - r_b) / length, -0.99, 0.99) : 0.0;
  const double alpha = std::asin(s);
  std::vector<std::pair<double, double>> profile;  // (radius, z)
  for (int i = 0; i <= rings; ++i) {  // lower cap: −π/2 … α
    const double t = -kPi / 2 + (alpha + kPi / 2) * i / rings;
    const double z = r_a * std::sin(t);
    profile.emplace_back(r_a * std::cos(t), z < 0 ? cap_a_depth * z : z);
  }
  for (int i = 0; i <= rings; ++i) {  // upper cap: α … π/2
    const double t = alpha + (kPi / 2 - alpha) * i / rings;
    const double z = r_b * std::sin(t);
    profile.emplace_back(r_b * std::cos(t), length + (z > 0 ? cap_b_depth * z : z));
  }
  const int rows = static_cast<int>(profile.size());
  for (const auto& [r, z] : profile)
    for (int j = 0; j < slices; ++j) {
      const double phi = 2 * kPi * j / slices;
      push(m, Vec3(r * std::cos(phi), r * std::sin(phi), z));
    }
  grid_faces(m, rows, slices);
  return m;
}


MeshData rounded_box(const Vec3& half, double e, int slices, int stacks) {
  MeshData m;
  m.name = "rounded_box";
  auto spow = [e](double v) { return std::copysign(std::pow(std::abs(v), e), v); };
  for (int i = 0; i <= stacks; ++i) {
    const double theta = -kPi / 2 + kPi * i / stacks;  // −z … +z
    for (int j = 0; j < slices; ++j) {
      const double phi = 2 * kPi * j / slices;
      const double ct = spow(std::cos(theta)), st = spow(std::sin(theta));
      push(m, Vec3(half.x() * ct * spow(std::cos(phi)), half.y() * ct * spow(std::sin(phi)),
                   half.z() * st));
    }
  }
  grid_faces(m, stacks + 1, slices);
  return m;
}

Status validate(const HandSkinParams& p) {
  auto range = [](const char* name, int v, int lo, int hi) -> Status {
    if (v >= lo && v <= hi) return Ok{};
    return Error{std::string("hand skin: ") + name + " must be in " + std::to_string(lo) + ".." +
                 std::to_string(hi) + ", got " + std::to_string(v)};
  };
  if (auto s = range("bone_slices", p.bone_slices, 6, 64); !s) return s;
  if (auto s = range("bone_rings", p.bone_rings, 2, 32); !s) return s;
  if (auto s = range("palm_slices", p.palm_slices, 8, 64); !s) return s;
  if (auto s = range("palm_stacks", p.palm_stacks, 4, 64); !s) return s;
  if (!(std::isfinite(p.taper) && p.taper >= 0 && p.taper < 1))
    return Error{"hand skin: taper must be in [0, 1), got " + std::to_string(p.taper)};
  if (!(std::isfinite(p.palm_fullness) && p.palm_fullness > 0 && p.palm_fullness <= 3))
    return Error{"hand skin: palm_fullness must be in (0, 3], got " + std::to_string(p.palm_fullness)};
  if (!(std::isfinite(p.palm_wrist_breadth) && p.palm_wrist_breadth >= 0.5 && p.palm_wrist_breadth <= 1))
    return Error{"hand skin: palm_wrist_breadth must be in [0.5, 1], got " + std::to_string(p.palm_wrist_breadth)};
  if (!(std::isfinite(p.forearm_breadth) && p.forearm_breadth >= 0.4 && p.forearm_breadth <= 1))
    return Error{"hand skin: forearm_breadth must be in [0.4, 1], got " + std::to_string(p.forearm_breadth)};
  if (!(std::isfinite(p.forearm_depth) && p.forearm_depth >= 0.4 && p.forearm_depth <= 1))
    return Error{"hand skin: forearm_depth must be in [0.4, 1], got " + std::to_string(p.forearm_depth)};
  if (!(std::isfinite(p.forearm_cap_depth) && p.forearm_cap_depth > 0 && p.forearm_cap_depth <= 1))
    return Error{"hand skin: forearm_cap_depth must be in (0, 1], got " + std::to_string(p.forearm_cap_depth)};
  if (p.bracelet && !(std::isfinite(p.bracelet_width_m) && p.bracelet_width_m > 0 && p.bracelet_width_m < 0.1))
    return Error{"hand skin: bracelet_width_m must be in (0, 0.1) m, got " + std::to_string(p.bracelet_width_m)};
  if (p.bracelet && !(std::isfinite(p.bracelet_offset_m) && p.bracelet_offset_m >= 0 && p.bracelet_offset_m < 0.1))
    return Error{"hand skin: bracelet_offset_m must be in [0, 0.1) m, got " + std::to_string(p.bracelet_offset_m)};
  if (!(std::isfinite(p.forearm_length_m) && p.forearm_length_m >= 0 && p.forearm_length_m <= 0.5))
    return Error{"hand skin: forearm_length_m must be in [0, 0.5] m, got " +
                 std::to_string(p.forearm_length_m)};
  return Ok{};
}

HandSkin build_hand_skin(const hand::HandModel& model, const HandSkinParams& p,
                         std::vector<MeshData>* meshes) {
  HandSkin skin;
  // Bone lengths are fixed by the shape: measure them at the zero pose.
  const hand::HandRenderShapes rest = hand::hand_render_shapes(model, hand::HandParams{});
  for (const hand::Capsule& c : rest.capsules) {
    const double len = (c.p_W_b - c.p_W_a).norm();
    meshes->push_back(tapered_segment((1 + p.taper) * c.radius, (1 - p.taper) * c.radius, len,
                                      p.bone_slices, p.bone_rings));
    skin.bones.push_back({static_cast<int>(meshes->size()) - 1, c.finger});
  }
  const Vec3 h = rest.boxes.at(0).half_extents;
  // The palm's skin reaches back to the wrist: the skeleton's palm box starts at the carpus (a
  // centimetre or so from the wrist), the hand's flesh does not, and the forearm's flattened end
  // (forearm_cap_depth) no longer fills the gap. The box mesh grows toward the wrist by the gap
  // and its centre moves by half of it, in the box frame (the axes of H). It also narrows toward
  // the wrist: palm_wrist_breadth of its breadth at the wrist end, full breadth from halfway to
  // the knuckles on, smoothly.
  const hand::PalmBox& box = model.shape.palm;
  const double gap = p.palm_reaches_wrist ? std::max(0.0, box.p_H_centre.y() - box.half_extents.y()) : 0.0;
  const double half_y = h.y() * 1.02 + 0.5 * gap;
  MeshData palm = rounded_box(Vec3(1.05 * h.x(), half_y, p.palm_fullness * h.z()), 0.45, p.palm_slices,
                              p.palm_stacks);
  for (std::size_t k = 0; k + 2 < palm.vertices.size(); k += 3) {
    const double t = std::clamp((palm.vertices[k + 1] + half_y) / half_y, 0.0, 1.0);  // 0 wrist, 1 halfway
    const double smooth = t * t * (3 - 2 * t);
    palm.vertices[k] *= static_cast<float>(p.palm_wrist_breadth + (1 - p.palm_wrist_breadth) * smooth);
    palm.vertices[k + 1] -= static_cast<float>(0.5 * gap);
  }
  meshes->push_back(std::move(palm));
  skin.palm_mesh = static_cast<int>(meshes->size()) - 1;
  // The forearm: an elliptic section, forearm_breadth of the palm's half breadth across and
  // forearm_depth of that deep, widening by 15 % over its length toward the elbow.
  skin.wrist_half_breadth = p.forearm_breadth * h.x();
  skin.wrist_half_depth = p.forearm_depth * skin.wrist_half_breadth;
  const int arm_slices = std::max(p.bone_slices, 16);
  if (p.forearm_length_m > 0) {
    MeshData arm = tapered_segment(skin.wrist_half_breadth, 1.15 * skin.wrist_half_breadth, p.forearm_length_m, arm_slices,
                                   p.bone_rings, p.forearm_cap_depth);
    flatten_y(&arm, p.forearm_depth);
    meshes->push_back(std::move(arm));
    skin.forearm_mesh = static_cast<int>(meshes->size()) - 1;
  }
  if (p.bracelet) {
    // A band 2 mm proud of the forearm where it sits, with nearly flat ends.
    const double grow = p.forearm_length_m > 0 ? 0.15 * p.bracelet_offset_m / p.forearm_length_m : 0;
    const double a = skin.wrist_half_breadth * (1 + grow) + 0.002, b = skin.wrist_half_depth * (1 + grow) + 0.002;
    MeshData band = tapered_segment(a, a, p.bracelet_width_m, arm_slices, 2, 0.05, 0.05);
    flatten_y(&band, b / a);
    meshes->push_back(std::move(band));
    skin.bracelet_mesh = static_cast<int>(meshes->size()) - 1;
  }
  return skin;
}

void pose_hand_skin(const hand::HandModel& model, const HandSkin& skin, const hand::HandParams& q,
                    const HandSkinParams& p, SceneSnapshot* scene, const Vec3* toward_elbow_W) {
  const hand::HandRenderShapes shapes = hand::hand_render_shapes(model, q);
  const int hand = static_cast<int>(model.side);
  auto add = [&](Shape s, int finger, const std::array<float, 3>& colour) {
    s.hand = hand;
    s.finger = finger;
    s.rgba = rgba(colour);
    scene->shapes.push_back(s);
  };
  for (std::size_t i = 0; i < shapes.capsules.size() && i < skin.bones.size(); ++i) {
    const hand::Capsule& c = shapes.capsules[i];
    Shape s;
    s.type = Shape::Type::kMesh;
    s.mesh = skin.bones[i].mesh;
    s.X_WS = along(c.p_W_a, c.p_W_b - c.p_W_a);
    add(s, c.finger, p.skin_rgb);
  }
  Shape palm;
  palm.type = Shape::Type::kMesh;
  palm.mesh = skin.palm_mesh;
  palm.X_WS = shapes.boxes.at(0).X_WB;
  add(palm, kPalmPart, p.skin_rgb);

  const Mat3 R_WH = hand::rotation_from_vector(q.r_W_hand());
  // The forearm's frame as if in line with the hand, then bent at the wrist onto toward_elbow_W.
  Mat3 R_arm = R_WH;
  if (toward_elbow_W) R_arm = hand::wrist_bend(R_WH, *toward_elbow_W) * R_WH;
  const Vec3 toward_elbow = -R_arm.col(1);
  if (skin.forearm_mesh >= 0) {
    Shape arm;
    arm.type = Shape::Type::kMesh;
    arm.mesh = skin.forearm_mesh;
    arm.X_WS = forearm_frame(q.p_W_wrist(), R_arm);
    add(arm, kForearmPart, p.skin_rgb);
  }
  if (skin.bracelet_mesh < 0 || !p.bracelet) return;
  Shape bracelet;
  bracelet.type = Shape::Type::kMesh;
  bracelet.mesh = skin.bracelet_mesh;
  bracelet.X_WS = forearm_frame(q.p_W_wrist() + (p.bracelet_offset_m - 0.5 * p.bracelet_width_m) * toward_elbow, R_arm);
  add(bracelet, kBraceletPart, p.bracelet_rgb);
}

}  // namespace spidar::render
