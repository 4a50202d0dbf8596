#include "primitive_mesh.hpp"

#include <cmath>
#include <numbers>

#include <Eigen/Geometry>

namespace spidar::render {
namespace {

void push_vertex(CpuMesh& m, const Eigen::Vector3f& p, const Eigen::Vector3f& n) {
  m.vertices.insert(m.vertices.end(), {p.x(), p.y(), p.z(), n.x(), n.y(), n.z()});
}
std::uint32_t vertex_count(const CpuMesh& m) {
  return static_cast<std::uint32_t>(m.vertices.size() / 6);
}

}  // namespace

CpuMesh unit_box() {
  CpuMesh m;
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign = -1; sign <= 1; sign += 2) {
      Eigen::Vector3f n = Eigen::Vector3f::Zero();
      n[axis] = static_cast<float>(sign);
      // Two tangents with t1 × t2 = n, so the corners below run counter-clockwise about n.
      Eigen::Vector3f t1 = Eigen::Vector3f::Zero();
      t1[(axis + 1) % 3] = 1.f;
      const Eigen::Vector3f t2 = n.cross(t1);
      const std::uint32_t base = vertex_count(m);
      const float c[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
      for (const auto& uv : c) push_vertex(m, n + uv[0] * t1 + uv[1] * t2, n);
      m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    }
  }
  return m;
}

CpuMesh unit_sphere(int slices, int stacks) {
  CpuMesh m;
  const float pi = std::numbers::pi_v<float>;
  for (int i = 0; i <= stacks; ++i) {
    const float theta = pi * static_cast<float>(i) / static_cast<float>(stacks);  // from +z
    for (int j = 0; j <= slices; ++j) {
      const float phi = 2 * pi * static_cast<float>(j) / static_cast<float>(slices);
      const Eigen::Vector3f p(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                              std::cos(theta));
      push_vertex(m, p, p);
    }
  }
  const auto row = static_cast<std::uint32_t>(slices + 1);
  for (int i = 0; i < stacks; ++i) {
    for (int j = 0; j < slices; ++j) {
      const std::uint32_t a = static_cast<std::uint32_t>(i) * row + static_cast<std::uint32_t>(j);
      const std::uint32_t b = a + row;
      // Going down in theta and around in phi: (a, b, b+1) is counter-clockwise from outside.
      m.indices.insert(m.indices.end(), {a, b, b + 1, a, b + 1, a + 1});
    }
  }
  return m;
}

CpuMesh unit_capsule_template(int slices, int stacks_per_cap) {
  CpuMesh m;
  const float pi = std::numbers::pi_v<float>;
  // Rows from the south pole to the equator (z = −ε), then from the equator (z = +ε) north.
  std::vector<float> elevations;
  for (int i = 0; i <= stacks_per_cap; ++i)
    elevations.push_back(-pi / 2 + (pi / 2) * static_cast<float>(i) / static_cast<float>(stacks_per_cap));
  for (int i = 0; i <= stacks_per_cap; ++i)
    elevations.push_back((pi / 2) * static_cast<float>(i) / static_cast<float>(stacks_per_cap));
  const std::size_t rows = elevations.size();
  // The polygon of `slices` sides inscribed in the unit circle is, averaged over the roll about
  // its axis, N sin(π/N)·2/π as wide as the circle (its mean width is its perimeter over π): the
  // vertices lie that much further out, so that the outline is as wide as the capsule on average
  // (within ±(1/cos(π/N) − 1)/2 at any roll).
  const auto n_slices = static_cast<float>(slices);
  const float widen = pi / (n_slices * std::sin(pi / n_slices));
  for (std::size_t i = 0; i < rows; ++i) {
    const float t = elevations[i];
    const float z_eps = i <= static_cast<std::size_t>(stacks_per_cap) ? -1e-6f : 1e-6f;
    for (int j = 0; j <= slices; ++j) {
      const float phi = 2 * pi * static_cast<float>(j) / static_cast<float>(slices);
      const Eigen::Vector3f n(std::cos(t) * std::cos(phi), std::cos(t) * std::sin(phi), std::sin(t));
      Eigen::Vector3f p = widen * n;
      if (std::abs(p.z()) < 1e-6f) p.z() = z_eps;
      push_vertex(m, p, n);
    }
  }
  const auto row = static_cast<std::uint32_t>(slices + 1);
  for (std::size_t i = 0; i + 1 < rows; ++i) {
    for (int j = 0; j < slices; ++j) {
      const std::uint32_t a = static_cast<std::uint32_t>(i) * row + static_cast<std::uint32_t>(j);
      const std::uint32_t b = a + row;  // the next row north
      // Rows run south to north and columns counter-clockwise about z: (a, a+1, b+1) and
      // (a, b+1, b) are counter-clockwise seen from outside.
      m.indices.insert(m.indices.end(), {a, a + 1, b + 1, a, b + 1, b});
    }
  }
  return m;
}

CpuMesh unit_cylinder(int slices) {
  CpuMesh m;
  const float pi = std::numbers::pi_v<float>;
  for (int j = 0; j <= slices; ++j) {
    const float phi = 2 * pi * static_cast<float>(j) / static_cast<float>(slices);
    const Eigen::Vector3f n(std::cos(phi), std::sin(phi), 0.f);
    push_vertex(m, n + Eigen::Vector3f(0, 0, -1), n);
    push_vertex(m, n + Eigen::Vector3f(0, 0, 1), n);
  }
  for (int j = 0; j < slices; ++j) {
    const auto a = static_cast<std::uint32_t>(2 * j);
    m.indices.insert(m.indices.end(), {a, a + 2, a + 3, a, a + 3, a + 1});
  }
  for (int sign = -1; sign <= 1; sign += 2) {
    const Eigen::Vector3f n(0, 0, static_cast<float>(sign));
    const std::uint32_t centre = vertex_count(m);
    push_vertex(m, n, n);
    for (int j = 0; j <= slices; ++j) {
      const float phi = 2 * pi * static_cast<float>(j) / static_cast<float>(slices);
      push_vertex(m, Eigen::Vector3f(std::cos(phi), std::sin(phi), n.z()), n);
    }
    for (int j = 0; j < slices; ++j) {
      const std::uint32_t a = centre + 1 + static_cast<std::uint32_t>(j);
      if (sign > 0)
        m.indices.insert(m.indices.end(), {centre, a, a + 1});
      else
        m.indices.insert(m.indices.end(), {centre, a + 1, a});
    }
  }
  return m;
}

CpuMesh unit_quad() {
  CpuMesh m;
  for (int sign = 1; sign >= -1; sign -= 2) {
    const Eigen::Vector3f n(0, 0, static_cast<float>(sign));
    const std::uint32_t base = vertex_count(m);
    const float c[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (const auto& uv : c) push_vertex(m, Eigen::Vector3f(uv[0], uv[1], 0.f), n);
    if (sign > 0)
      m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    else
      m.indices.insert(m.indices.end(), {base, base + 2, base + 1, base, base + 3, base + 2});
  }
  return m;
}

CpuMesh mesh_with_normals(const MeshData& mesh, double crease_deg) {
  CpuMesh m;
  const int nv = static_cast<int>(mesh.vertices.size() / 3);
  auto vertex = [&](int i) {
    return Eigen::Vector3f(mesh.vertices[3 * i], mesh.vertices[3 * i + 1], mesh.vertices[3 * i + 2]);
  };
  std::vector<std::array<int, 3>> faces;
  for (std::size_t f = 0; f + 2 < mesh.faces.size(); f += 3) {
    const std::array<int, 3> t{mesh.faces[f], mesh.faces[f + 1], mesh.faces[f + 2]};
    if (t[0] < 0 || t[1] < 0 || t[2] < 0 || t[0] >= nv || t[1] >= nv || t[2] >= nv) continue;
    faces.push_back(t);
  }
  std::vector<Eigen::Vector3f> area_normal(faces.size());  // |n| = 2 × area
  std::vector<std::vector<int>> faces_at(static_cast<std::size_t>(nv));
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const auto& t = faces[f];
    area_normal[f] = (vertex(t[1]) - vertex(t[0])).cross(vertex(t[2]) - vertex(t[0]));
    for (int k : t) faces_at[static_cast<std::size_t>(k)].push_back(static_cast<int>(f));
  }
  const float cos_crease = static_cast<float>(std::cos(crease_deg * std::numbers::pi / 180.0));
  for (std::size_t f = 0; f < faces.size(); ++f) {
    if (area_normal[f].squaredNorm() <= 0.f) continue;  // degenerate (e.g. at a pole): no pixels
    const Eigen::Vector3f nf = area_normal[f].normalized();
    for (int k : faces[f]) {
      Eigen::Vector3f n = Eigen::Vector3f::Zero();
      for (int g : faces_at[static_cast<std::size_t>(k)]) {
        const Eigen::Vector3f& ng = area_normal[static_cast<std::size_t>(g)];
        if (ng.squaredNorm() > 0.f && ng.normalized().dot(nf) >= cos_crease) n += ng;
      }
      push_vertex(m, vertex(k), n.squaredNorm() > 0 ? n.normalized() : nf);
    }
    const std::uint32_t base = vertex_count(m) - 3;
    m.indices.insert(m.indices.end(), {base, base + 1, base + 2});
  }
  return m;
}

void snapshot_mesh(const MeshData& mesh, CpuMesh* out) {
  const std::size_t floats = mesh.vertices.size() / 3 * 3;
  if (mesh.normals.size() != mesh.vertices.size()) {
    *out = mesh_with_normals(mesh);
    return;
  }
  out->vertices.resize(2 * floats);
  for (std::size_t v = 0; v < floats / 3; ++v)
    for (std::size_t k = 0; k < 3; ++k) {
      out->vertices[6 * v + k] = mesh.vertices[3 * v + k];
      out->vertices[6 * v + 3 + k] = mesh.normals[3 * v + k];
    }
  const int nv = static_cast<int>(floats / 3);
  out->indices.clear();
  for (std::size_t f = 0; f + 2 < mesh.faces.size(); f += 3) {
    const int a = mesh.faces[f], b = mesh.faces[f + 1], c = mesh.faces[f + 2];
    if (a < 0 || b < 0 || c < 0 || a >= nv || b >= nv || c >= nv) continue;
    out->indices.insert(out->indices.end(), {static_cast<std::uint32_t>(a),
                                             static_cast<std::uint32_t>(b),
                                             static_cast<std::uint32_t>(c)});
  }
}

}  // namespace spidar::render
