#pragma once
// Triangle meshes of the unit primitives the renderer scales per shape, and of snapshot meshes
// with normals. Vertices are interleaved x y z nx ny nz (shape frame); triangles are
// counter-clockwise seen from outside.
#include <cstdint>
#include <vector>

#include "spidar/core/scene_snapshot.hpp"

namespace spidar::render {

struct CpuMesh {
  std::vector<float> vertices;         ///< 6 floats per vertex: position, normal
  std::vector<std::uint32_t> indices;  ///< 3 per triangle
};

/// [−1, 1]³ with flat faces (24 vertices).
CpuMesh unit_box();
/// Radius 1 centred at the origin.
CpuMesh unit_sphere(int slices = 24, int stacks = 16);
/// A capsule of radius 1 and length 0: a unit sphere split at its equator into two hemispheres
/// whose equator rows sit at z = ±1e−6. The vertex shader moves each vertex by sign(z) times the
/// instance's half length (in radii), which stretches the equator band into the cylinder: one
/// instanced draw per capsule batch instead of a cylinder and two spheres. The vertices lie
/// π / (slices sin(π/slices)) from the centre instead of 1 (1.012 for 12 slices), so that the
/// outline of the polygon is as wide as the round capsule's, averaged over its roll.
CpuMesh unit_capsule_template(int slices = 12, int stacks_per_cap = 4);
/// Radius 1, z in [−1, 1], with flat caps.
CpuMesh unit_cylinder(int slices = 24);
/// The square [−1, 1]² in z = 0, both sides (normals ±z).
CpuMesh unit_quad();
/// A snapshot mesh with normals: each corner gets the area-weighted mean normal of the faces
/// at its vertex that lie within `crease_deg` of its own face, so curved surfaces look smooth and
/// edges (e.g. a cubelet's bevels) stay sharp. Out-of-range indices are skipped.
CpuMesh mesh_with_normals(const MeshData& mesh, double crease_deg = 40.0);
/// A snapshot mesh as the renderer uploads it, into `out` (its buffers reused): with the mesh's
/// own normals (MeshData::normals, one per vertex) the vertices stay shared and only triangles
/// with indices out of range are dropped; without them, mesh_with_normals(mesh).
void snapshot_mesh(const MeshData& mesh, CpuMesh* out);

}  // namespace spidar::render
