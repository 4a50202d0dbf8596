#pragma once
// Private to sim: the skin's building block, a closed tube swept along a straight axis through
// cross-sections that change along it (the anatomical hand's digits, palm, webs, forearm and
// bracelet are all such tubes), and a thin shell lying on a tube's surface (the nails).
//
// Tube frame T (given in the hand frame H): the axis is y_T, z_T dorsal, x_T = y_T × z_T. A
// station at axial position s [m] has a centre offset (shift_x, shift_z) from the axis, a tilt
// [rad] of its cross-section plane about z_T (the palm's knuckle line is slanted), and a
// superellipse cross-section: at angle θ, x = half_x·sgn(cos θ)|cos θ|^e,
// z = half(z)·sgn(sin θ)|sin θ|^e with half = half_dorsal above the centre and half_palmar below
// (e = 1 an ellipse, e < 1 boxier). Between stations everything is interpolated linearly. Beyond
// the first and the last station the tube closes with a dome of the given length (a quarter
// ellipse in profile ending in one pole vertex; length 0: a flat cap).
#include <functional>
#include <vector>

#include "spidar/core/types.hpp"
#include "spidar/sim/anatomical_hand.hpp"

namespace spidar::sim::skin {

struct Station {
  double s = 0;           // along y_T [m]
  double half_x = 0.01;   // [m]
  double half_dorsal = 0.01;
  double half_palmar = 0.01;
  double exponent = 1.0;
  double shift_x = 0;     // centre offset [m]
  double shift_z = 0;
  double tilt = 0;        // [rad] about z_T
};

struct Tube {
  Vec3 p_H_origin = Vec3::Zero();
  Mat3 R_HT = Mat3::Identity();
  std::vector<Station> stations;  // increasing s, at least two
  double dome_start = 0;          // [m]
  double dome_end = 0;            // [m]
};

// A point of the surface in H: s may lie in the domes (s < first − dome_start or s > last +
// dome_end is clamped to the poles); θ as above.
Vec3 tube_point(const Tube& tube, double s, double theta);
// The outward unit normal there (numerical, from tube_point).
Vec3 tube_normal(const Tube& tube, double s, double theta);
// The station interpolated at s (clamped to the tube's body).
Station station_at(const Tube& tube, double s);

// A mesh under construction: positions in H, per-vertex weights, triangles counter-clockwise
// seen from outside (right-hand numbers).
struct Mesh {
  std::vector<Vec3> p_H;
  std::vector<BoneWeights> weights;
  std::vector<int> faces;
};

// Weights of a vertex from its axial position s and its position in H.
using WeightFn = std::function<BoneWeights(double s, const Vec3& p_H)>;

// Samples `tube` into `out` (appended): rings at every station, extra rings so that no gap
// exceeds `max_step` [m], `dome_rings` rings per dome, `slices` vertices per ring.
void sweep(const Tube& tube, int slices, double max_step, int dome_rings, const WeightFn& weights,
           Mesh* out);

// A closed shell on the tube's surface over s ∈ [s0, s1] and θ ∈ π/2 ± half_angle(s) (the
// dorsal side), its outer face `above` [m] over the skin, its inner face `below` under it.
void dorsal_shell(const Tube& tube, double s0, double s1,
                  const std::function<double(double s)>& half_angle, double above, double below,
                  int ns, int nt, const BoneWeights& weights, Mesh* out);

// Area-weighted smooth vertex normals of a mesh (unit; a vertex without faces gets +z).
std::vector<Vec3> smooth_normals(const Mesh& mesh);

// One bone with all the weight / two bones blended (w = weight of b).
BoneWeights rigid(int bone);
BoneWeights blend(int a, int b, double w);

}  // namespace spidar::sim::skin
