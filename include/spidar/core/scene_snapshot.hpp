#pragma once
/// A neutral picture of a scene for renderers: shapes with poses and colours, and the meshes they
/// use. Physics exports it; render draws it; neither knows the other.
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "spidar/core/pose.hpp"

namespace spidar {

struct MeshData {
  std::string name;
  std::vector<float> vertices;  ///< x y z per vertex [m], in the shape's frame
  std::vector<int> faces;       ///< three vertex indices per triangle
  /// Optional unit normals, x y z per vertex (same count as `vertices`), in the shape's frame.
  /// Empty: the renderer derives them from the faces (smooth within a crease angle).
  std::vector<float> normals;
  /// Change counter of a mesh whose contents change after it was first drawn (e.g. a skinned
  /// hand posed every frame): whoever edits `vertices`, `normals` or `faces` in place increments
  /// it, and a renderer that has the mesh uploaded uploads it again when the number differs from
  /// the one it uploaded. Static meshes leave it at 0.
  std::uint64_t version = 0;
};

struct Shape {
  enum class Type { kBox, kSphere, kCapsule, kCylinder, kPlane, kMesh };
  Type type = Type::kBox;
  /// Box: half sizes; sphere: (r, ·, ·); capsule/cylinder: (r, half length along z, ·);
  /// plane: (half x, half y, ·) [m].
  Vec3 size = Vec3::Zero();
  Pose X_WS;                                    ///< pose of the shape in world
  std::array<float, 4> rgba{0.5f, 0.5f, 0.5f, 1.f};
  int mesh = -1;                                ///< index into SceneSnapshot::meshes
  int body = -1;                                ///< owner body id (physics), for picking
  int hand = -1;                                ///< 0 left, 1 right for hand shapes, else −1
  int finger = -1;                              ///< finger index for hand shapes, else −1
};

struct SceneSnapshot {
  double t_s = 0;                               ///< simulation time [s]
  std::vector<Shape> shapes;
  std::shared_ptr<const std::vector<MeshData>> meshes;  ///< shared between snapshots
};

}  // namespace spidar
