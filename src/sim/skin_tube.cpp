#include "skin_tube.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace spidar::sim::skin {
namespace {

constexpr double kPi = std::numbers::pi;

double spow(double v, double e) { return std::copysign(std::pow(std::abs(v), e), v); }

// Offset of the cross-section point at θ from the station's centre, in the station's plane.
Vec3 profile(const Station& st, double theta) {
  const double c = std::cos(theta), s = std::sin(theta);
  const double half_z = s >= 0 ? st.half_dorsal : st.half_palmar;
  const double x = st.half_x * spow(c, st.exponent);
  const double z = half_z * spow(s, st.exponent);
  const double ct = std::cos(st.tilt), sn = std::sin(st.tilt);
  return Vec3(ct * x, sn * x, z);  // tilted about z_T
}

// Direction of the station plane's normal (y_T tilted about z_T), in T.
Vec3 plane_normal(const Station& st) { return Vec3(-std::sin(st.tilt), std::cos(st.tilt), 0.0); }

}  // namespace

Station station_at(const Tube& tube, double s) {
  const auto& v = tube.stations;
  if (s <= v.front().s) return v.front();
  if (s >= v.back().s) return v.back();
  std::size_t i = 1;
  while (v[i].s < s) ++i;
  const Station& a = v[i - 1];
  const Station& b = v[i];
  const double t = (s - a.s) / (b.s - a.s);
  auto mix = [t](double x, double y) { return (1 - t) * x + t * y; };
  Station o;
  o.s = s;
  o.half_x = mix(a.half_x, b.half_x);
  o.half_dorsal = mix(a.half_dorsal, b.half_dorsal);
  o.half_palmar = mix(a.half_palmar, b.half_palmar);
  o.exponent = mix(a.exponent, b.exponent);
  o.shift_x = mix(a.shift_x, b.shift_x);
  o.shift_z = mix(a.shift_z, b.shift_z);
  o.tilt = mix(a.tilt, b.tilt);
  return o;
}

Vec3 tube_point(const Tube& tube, double s, double theta) {
  const Station& first = tube.stations.front();
  const Station& last = tube.stations.back();
  Vec3 p_T;
  auto dome = [&](const Station& st, double along, double length, double sign) {
    // Quarter ellipse: the profile shrinks with cos φ as the centre moves out by length·sin φ.
    const double u = length > 0 ? std::clamp(along / length, 0.0, 1.0) : 1.0;
    const double scale = std::sqrt(std::max(0.0, 1.0 - u * u));
    const Vec3 centre(st.shift_x, st.s, st.shift_z);
    return Vec3(centre + sign * u * length * plane_normal(st) + scale * profile(st, theta));
  };
  if (s < first.s) {
    p_T = dome(first, first.s - s, tube.dome_start, -1.0);
  } else if (s > last.s) {
    p_T = dome(last, s - last.s, tube.dome_end, +1.0);
  } else {
    const Station st = station_at(tube, s);
    p_T = Vec3(st.shift_x, s, st.shift_z) + profile(st, theta);
  }
  return tube.p_H_origin + tube.R_HT * p_T;
}

Vec3 tube_normal(const Tube& tube, double s, double theta) {
  const double ds = 1e-4, dt = 1e-3;
  const Vec3 a = tube_point(tube, s + ds, theta) - tube_point(tube, s - ds, theta);
  const Vec3 b = tube_point(tube, s, theta + dt) - tube_point(tube, s, theta - dt);
  // θ runs from x_T toward z_T, i.e. clockwise seen from +y_T: outward = ∂s × ∂θ.
  const Vec3 n = a.cross(b);
  return n.norm() > 0 ? Vec3(n.normalized()) : Vec3(tube.R_HT.col(2));
}

void sweep(const Tube& tube, int slices, double max_step, int dome_rings, const WeightFn& weights,
           Mesh* out) {
  // Axial positions of the rings: dome (from the start pole, exclusive), body, dome.
  std::vector<double> rings;
  const double s_first = tube.stations.front().s, s_last = tube.stations.back().s;
  auto dome_positions = [&](double length, double sign, double from) {
    std::vector<double> r;
    if (length <= 0) return r;
    for (int k = dome_rings - 1; k >= 1; --k) {
      const double phi = 0.5 * kPi * k / dome_rings;
      r.push_back(from + sign * length * std::sin(phi));
    }
    return r;
  };
  for (double s : dome_positions(tube.dome_start, -1.0, s_first)) rings.push_back(s);
  for (std::size_t i = 0; i + 1 < tube.stations.size(); ++i) {
    const double a = tube.stations[i].s, b = tube.stations[i + 1].s;
    const int n = std::max(1, static_cast<int>(std::ceil((b - a) / max_step)));
    for (int k = 0; k < n; ++k) rings.push_back(a + (b - a) * k / n);
  }
  rings.push_back(s_last);
  {
    auto end = dome_positions(tube.dome_end, +1.0, s_last);
    std::reverse(end.begin(), end.end());
    rings.insert(rings.end(), end.begin(), end.end());
  }

  const int base = static_cast<int>(out->p_H.size());
  auto add = [&](double s, const Vec3& p) {
    out->p_H.push_back(p);
    out->weights.push_back(weights(s, p));
    return static_cast<int>(out->p_H.size()) - 1;
  };
  // Start pole, rings, end pole.
  const double s_start_pole = s_first - tube.dome_start;
  const double s_end_pole = s_last + tube.dome_end;
  const Station& first = tube.stations.front();
  const Station& last = tube.stations.back();
  const int start_pole = add(s_start_pole, tube.p_H_origin + tube.R_HT * (Vec3(first.shift_x, first.s, first.shift_z) -
                                                                          tube.dome_start * plane_normal(first)));
  for (double s : rings)
    for (int j = 0; j < slices; ++j) add(s, tube_point(tube, s, 2 * kPi * j / slices));
  const int end_pole = add(s_end_pole, tube.p_H_origin + tube.R_HT * (Vec3(last.shift_x, last.s, last.shift_z) +
                                                                      tube.dome_end * plane_normal(last)));
  auto at = [&](std::size_t ring, int j) {
    return base + 1 + static_cast<int>(ring) * slices + (j % slices);
  };
  auto tri = [&](int a, int b, int c) { out->faces.insert(out->faces.end(), {a, b, c}); };
  for (int j = 0; j < slices; ++j) tri(start_pole, at(0, j), at(0, j + 1));
  for (std::size_t i = 0; i + 1 < rings.size(); ++i)
    for (int j = 0; j < slices; ++j) {
      const int a = at(i, j), b = at(i, j + 1), c = at(i + 1, j + 1), d = at(i + 1, j);
      tri(a, c, b);
      tri(a, d, c);
    }
  const std::size_t last_ring = rings.size() - 1;
  for (int j = 0; j < slices; ++j) tri(end_pole, at(last_ring, j + 1), at(last_ring, j));
}

void dorsal_shell(const Tube& tube, double s0, double s1,
                  const std::function<double(double s)>& half_angle, double above, double below,
                  int ns, int nt, const BoneWeights& weights, Mesh* out) {
  const int base = static_cast<int>(out->p_H.size());
  // Grid: i along s, j across (θ from π/2 − a to π/2 + a); the outer layer, then the inner.
  for (int layer = 0; layer < 2; ++layer)
    for (int i = 0; i <= ns; ++i) {
      const double s = s0 + (s1 - s0) * i / ns;
      const double a = half_angle(s);
      for (int j = 0; j <= nt; ++j) {
        const double theta = 0.5 * kPi - a + 2 * a * j / nt;
        const Vec3 n = tube_normal(tube, s, theta);
        out->p_H.push_back(tube_point(tube, s, theta) + (layer == 0 ? above : -below) * n);
        out->weights.push_back(weights);
      }
    }
  const int row = nt + 1, layer_size = (ns + 1) * row;
  auto at = [&](int layer, int i, int j) { return base + layer * layer_size + i * row + j; };
  // a b c d run clockwise seen from outside; the triangles are emitted the other way round.
  // (Along s is ∂s, across is ∂θ, and the outer face's outward normal is ∂s × ∂θ.)
  auto quad = [&](int a, int b, int c, int d) {
    out->faces.insert(out->faces.end(), {a, c, b, a, d, c});
  };
  for (int i = 0; i < ns; ++i)
    for (int j = 0; j < nt; ++j) {
      quad(at(0, i, j), at(0, i, j + 1), at(0, i + 1, j + 1), at(0, i + 1, j));
      quad(at(1, i, j), at(1, i + 1, j), at(1, i + 1, j + 1), at(1, i, j + 1));
    }
  // Rims: the four edges joining the layers.
  for (int i = 0; i < ns; ++i) {
    quad(at(0, i, 0), at(0, i + 1, 0), at(1, i + 1, 0), at(1, i, 0));
    quad(at(0, i, nt), at(1, i, nt), at(1, i + 1, nt), at(0, i + 1, nt));
  }
  for (int j = 0; j < nt; ++j) {
    quad(at(0, 0, j), at(1, 0, j), at(1, 0, j + 1), at(0, 0, j + 1));
    quad(at(0, ns, j), at(0, ns, j + 1), at(1, ns, j + 1), at(1, ns, j));
  }
}

std::vector<Vec3> smooth_normals(const Mesh& mesh) {
  std::vector<Vec3> n(mesh.p_H.size(), Vec3::Zero());
  for (std::size_t f = 0; f + 2 < mesh.faces.size(); f += 3) {
    const int a = mesh.faces[f], b = mesh.faces[f + 1], c = mesh.faces[f + 2];
    const Vec3 area = (mesh.p_H[b] - mesh.p_H[a]).cross(mesh.p_H[c] - mesh.p_H[a]);
    n[a] += area;
    n[b] += area;
    n[c] += area;
  }
  for (Vec3& v : n) v = v.norm() > 0 ? Vec3(v.normalized()) : Vec3::UnitZ();
  return n;
}

BoneWeights rigid(int bone) {
  BoneWeights w;
  w.bone = {static_cast<std::uint8_t>(bone), 0, 0};
  w.weight = {1.f, 0.f, 0.f};
  return w;
}

BoneWeights blend(int a, int b, double w) {
  w = std::clamp(w, 0.0, 1.0);
  BoneWeights out;
  out.bone = {static_cast<std::uint8_t>(a), static_cast<std::uint8_t>(b), 0};
  out.weight = {static_cast<float>(1 - w), static_cast<float>(w), 0.f};
  return out;
}

}  // namespace spidar::sim::skin
