#pragma once
/// A neutral picture of a scene for renderers: shapes with poses and colours, and the meshes they
/// use. Physics exports it; render draws it; neither knows the other.
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "spidar/core/pose.hpp"

namespace spidar {

struct MeshData {
  std::string name;
  std::vector<float> vertices;  ///< x y z per vertex [m], in the shape's frame
  std::vector<int> faces;       ///< three vertex indices per triangle
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
