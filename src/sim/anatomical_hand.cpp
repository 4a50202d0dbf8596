// The anatomical hand's geometry: the parts as tubes and shells on the rest skeleton, their bone
// weights, and the palm's pads. Numbers are fractions of the hand's breadth W or length L unless
// they carry a unit.
#include "spidar/sim/anatomical_hand.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "skin_tube.hpp"
#include "spidar/hand/kinematics.hpp"
#include "spidar/render/hand_skin.hpp"  // part ids only (kPalmPart, kBraceletPart, kForearmPart)

namespace spidar::sim {
namespace {

using skin::Station;
using skin::Tube;

double smoothstep(double a, double b, double x) {
  const double t = std::clamp((x - a) / (b - a), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

// Breadths of a finger across its joints and segments [fraction of W] (anthropometric means
// scaled to a 0.087 m palm: index PIP ≈ 21 mm, DIP ≈ 18.5 mm, ...): base inside the palm, MCP,
// middle of the proximal phalanx, PIP, middle of the middle phalanx, DIP, pad of the distal one.
struct FingerBreadths {
  std::array<double, 7> b;
};
constexpr std::array<FingerBreadths, 4> kFingerBreadths = {{
    {{0.25, 0.245, 0.222, 0.238, 0.205, 0.212, 0.205}},  // index
    {{0.26, 0.252, 0.230, 0.246, 0.214, 0.218, 0.210}},  // middle
    {{0.24, 0.236, 0.214, 0.228, 0.198, 0.202, 0.196}},  // ring
    {{0.21, 0.206, 0.186, 0.198, 0.174, 0.178, 0.170}},  // little
}};

// Joints of one digit along its straight rest axis: arc positions s of the joints [m] (the first
// is the digit's base joint at 0), the bones before and after each, the blend half-widths.
struct Chain {
  std::array<double, 4> s{};      // base joint, next, next, tip
  std::array<int, 4> bone{};      // bone before joint 0, then after joints 0, 1, 2
  std::array<double, 3> blend{};  // half-width of the blend at joints 0, 1, 2 [m]
  double centre0 = 0;             // the first joint's blend is centred here (s) [m]
};

BoneWeights chain_weights(const Chain& c, double s) {
  double centre[3] = {c.centre0, c.s[1], c.s[2]};
  for (int j = 0; j < 3; ++j) {
    const double h = c.blend[j];
    if (s < centre[j] + h) {
      if (s <= centre[j] - h) return skin::rigid(c.bone[j]);
      return skin::blend(c.bone[j], c.bone[j + 1], smoothstep(centre[j] - h, centre[j] + h, s));
    }
  }
  return skin::rigid(c.bone[3]);
}

struct Builder {
  const hand::HandModel& model;
  const AnatomicalHandParams& p;
  double W, L;
  hand::HandPoints rest;  // joints in H (right-hand numbers)
  AnatomicalHand out;
  std::array<Tube, hand::kFingerCount> digit_tube;
  std::array<Chain, hand::kFingerCount> chain;

  const Vec3& joint(int f, int k) const { return rest.p_W_joint[hand::joint_index(f, k)]; }
  const hand::DigitShape& digit(int f) const { return model.shape.digits[f]; }

  SkinnedPart& add_part(const std::string& name, HandPart kind, int finger,
                        const std::array<float, 3>& rgb, const skin::Mesh& m) {
    SkinnedPart part;
    part.name = name;
    part.kind = kind;
    part.finger = finger;
    part.rgb = rgb;
    const std::vector<Vec3> n = skin::smooth_normals(m);
    for (std::size_t i = 0; i < m.p_H.size(); ++i) {
      part.p_H_rest.push_back(m.p_H[i].cast<float>());
      part.n_H_rest.push_back(n[i].cast<float>());
    }
    part.weights = m.weights;
    part.faces = m.faces;
    if (model.side == hand::Side::kLeft)  // mirrored in world: wind the other way round
      for (std::size_t f = 0; f + 2 < part.faces.size(); f += 3) std::swap(part.faces[f + 1], part.faces[f + 2]);
    out.parts.push_back(std::move(part));
    return out.parts.back();
  }

  // --- digits ---

  void finger(int f) {
    const hand::DigitShape& d = digit(f);
    const auto& b = kFingerBreadths[static_cast<std::size_t>(f - 1)].b;
    const double L1 = d.length[1], L2 = d.length[2], L3 = d.length[3];
    const double tip = L1 + L2 + L3;
    auto st = [&](double s, double breadth, double dorsal, double palmar, double e) {
      Station x;
      x.s = s;
      x.half_x = 0.5 * breadth * W;
      x.half_dorsal = dorsal * breadth * W;
      x.half_palmar = palmar * breadth * W;
      x.exponent = e;
      return x;
    };
    Tube t;
    t.p_H_origin = joint(f, 0);
    t.R_HT = d.R_H_digit;
    const double pad = L1 + L2 + 0.45 * L3;
    const double last = std::max(pad + 0.001, tip - 0.45 * b[6] * W);
    t.stations = {
        st(-0.15 * W, b[0], 0.40, 0.42, 0.95),     // inside the palm
        st(0.0, b[1], 0.47, 0.45, 1.0),            // MCP knuckle
        st(0.5 * L1, b[2], 0.37, 0.47, 0.9),       // proximal phalanx
        st(L1, b[3], 0.45, 0.43, 1.0),             // PIP knuckle
        st(L1 + 0.5 * L2, b[4], 0.36, 0.45, 0.9),  // middle phalanx
        st(L1 + L2, b[5], 0.42, 0.42, 1.0),        // DIP
        st(pad, b[6], 0.36, 0.50, 0.9),            // finger pad
        st(last, 0.92 * b[6], 0.33, 0.42, 0.95),
    };
    t.dome_start = 0.06 * W;
    t.dome_end = tip + 0.0005 - last;
    Chain c;
    c.s = {0.0, L1, L1 + L2, tip};
    c.bone = {kPalmBone, phalanx_bone(f, 0), phalanx_bone(f, 1), phalanx_bone(f, 2)};
    c.blend = {0.28 * b[1] * W, 0.30 * b[3] * W, 0.28 * b[5] * W};
    c.centre0 = 0.0;
    add_digit(f, t, c);
  }

  void thumb() {
    const int f = hand::kThumb;
    const hand::DigitShape& d = digit(f);
    const double Lm = d.length[0], L1 = d.length[1], L2 = d.length[2];
    const double tip = Lm + L1 + L2;
    auto st = [&](double s, double hx, double hd, double hp, double e) {
      Station x;
      x.s = s;
      x.half_x = hx * W;
      x.half_dorsal = hd * W;
      x.half_palmar = hp * W;
      x.exponent = e;
      return x;
    };
    Tube t;
    t.p_H_origin = joint(f, 0);
    t.R_HT = d.R_H_digit;
    const double pad = Lm + L1 + 0.45 * L2;
    const double last = std::max(pad + 0.001, tip - 0.11 * W);
    t.stations = {
        st(-0.06 * W, 0.19, 0.13, 0.19, 0.9),  // thenar, in the palm
        st(0.35 * Lm, 0.17, 0.12, 0.18, 0.9),   // thenar mass on the metacarpal
        st(0.75 * Lm, 0.145, 0.11, 0.13, 0.9),
        st(Lm, 0.14, 0.125, 0.12, 1.0),         // MCP
        st(Lm + 0.5 * L1, 0.125, 0.10, 0.115, 0.9),
        st(Lm + L1, 0.13, 0.11, 0.105, 1.0),    // IP
        st(pad, 0.125, 0.095, 0.125, 0.9),      // pad
        st(last, 0.11, 0.085, 0.10, 0.95),
    };
    t.dome_start = 0.05 * W;
    t.dome_end = tip + 0.0005 - last;
    Chain c;
    c.s = {0.0, Lm, Lm + L1, tip};
    c.bone = {kPalmBone, kThumbMetacarpalBone, phalanx_bone(f, 0), phalanx_bone(f, 1)};
    c.blend = {0.35 * Lm, 0.13 * W, 0.09 * W};
    c.centre0 = 0.15 * Lm;  // the thenar mass stays partly with the palm
    add_digit(f, t, c);
  }

  void add_digit(int f, const Tube& t, const Chain& c) {
    digit_tube[f] = t;
    chain[f] = c;
    skin::Mesh m;
    skin::sweep(t, p.digit_slices, 0.004, 5, [&](double s, const Vec3&) { return chain_weights(c, s); },
                &m);
    static constexpr const char* kNames[] = {"thumb", "index", "middle", "ring", "little"};
    add_part(kNames[f], HandPart::kDigit, f, p.skin_rgb, m);
    out.tip_part[f] = static_cast<int>(out.parts.size()) - 1;
    out.tip_vertex[f] = static_cast<int>(m.p_H.size()) - 1;  // the end pole is the last vertex
  }

  void nail(int f) {
    const Tube& t = digit_tube[f];
    const Chain& c = chain[f];
    const double s_dip = c.s[2], tip = c.s[3];
    const double s0 = s_dip + 0.30 * (tip - s_dip);
    const double s1 = tip - 0.07 * W * (f == hand::kThumb ? 1.1 : 1.0);
    const double a_max = f == hand::kThumb ? 1.0 : 0.95;  // half the nail's angle [rad]
    auto half_angle = [=](double s) {
      const double u = (s - s0) / (s1 - s0);  // rounded at the cuticle, square at the free edge
      return a_max * std::sqrt(std::clamp(0.15 + u / 0.3, 0.0, 1.0));
    };
    skin::Mesh m;
    skin::dorsal_shell(t, s0, s1, half_angle, 0.0006, 0.0005, 6, 6, skin::rigid(c.bone[3]), &m);
    static constexpr const char* kNames[] = {"thumb_nail", "index_nail", "middle_nail", "ring_nail",
                                             "little_nail"};
    add_part(kNames[f], HandPart::kNail, f, p.nail_rgb, m);
  }

  // --- palm ---

  void palm() {
    const Vec3& mi = joint(hand::kIndex, 0);
    const Vec3& ml = joint(hand::kLittle, 0);
    const double y_k = 0.5 * (mi.y() + ml.y());
    const double x_k = 0.5 * ((mi.x() - 0.12 * W) + (ml.x() + 0.10 * W));
    const double tilt = std::atan2(ml.y() - mi.y(), ml.x() - mi.x());
    const double hx_k = 0.5 * ((ml - mi).norm() + 0.22 * W);
    auto st = [&](double s, double shift, double tl, double hx, double hd, double hp, double e) {
      Station x;
      x.s = s;
      x.shift_x = shift;
      x.tilt = tl;
      x.half_x = hx;
      x.half_dorsal = hd * W;
      x.half_palmar = hp * W;
      x.exponent = e;
      return x;
    };
    Tube t;
    t.stations = {
        st(0.0, 0.03 * W, 0.0, 0.34 * W, 0.19, 0.20, 0.85),  // wrist
        st(0.22 * y_k, 0.06 * W, 0.0, 0.43 * W, 0.15, 0.20, 0.65),
        st(0.50 * y_k, 0.08 * W, 0.0, 0.47 * W, 0.13, 0.18, 0.6),
        st(0.80 * y_k, 0.4 * 0.08 * W + 0.6 * x_k, 0.6 * tilt, 0.47 * W, 0.12, 0.16, 0.6),
        st(y_k, x_k, tilt, hx_k, 0.12, 0.14, 0.65),  // knuckle line
    };
    t.dome_start = 0.04 * W;
    t.dome_end = 0.09 * W;
    skin::Mesh m;
    skin::sweep(t, 36, 0.008, 4, [](double, const Vec3&) { return skin::rigid(kPalmBone); }, &m);

    // Pads on the palmar side, knuckles on the back: Gaussian bumps along ∓z_H.
    struct Bump {
      double x, y, sx, sy, amplitude;  // [m]
    };
    std::vector<Bump> palmar = {
        {-0.26 * W, 0.33 * y_k, 0.13 * W, 0.20 * y_k, 0.060 * W},  // thenar
        {0.42 * W, 0.38 * y_k, 0.10 * W, 0.25 * y_k, 0.045 * W},   // hypothenar
        {0.08 * W, 0.55 * y_k, 0.14 * W, 0.16 * y_k, -0.035 * W},  // the hollow of the palm
    };
    std::vector<Bump> dorsal;
    for (int f = hand::kIndex; f <= hand::kLittle; ++f) {
      const Vec3& m_f = joint(f, 0);
      palmar.push_back({m_f.x(), m_f.y() - 0.05 * W, 0.08 * W, 0.07 * W, 0.025 * W});  // pads
      dorsal.push_back({m_f.x(), m_f.y() - 0.02 * W, 0.055 * W, 0.05 * W, 0.025 * W});  // knuckles
    }
    auto sum = [](const std::vector<Bump>& bumps, const Vec3& q) {
      double h = 0;
      for (const Bump& b : bumps) {
        const double dx = (q.x() - b.x) / b.sx, dy = (q.y() - b.y) / b.sy;
        h += b.amplitude * std::exp(-0.5 * (dx * dx + dy * dy));
      }
      return h;
    };
    for (Vec3& q : m.p_H) {
      const double under = std::clamp(-q.z() / (0.15 * W), 0.0, 1.0);
      const double over = std::clamp(q.z() / (0.10 * W), 0.0, 1.0);
      q.z() += -under * sum(palmar, q) + over * sum(dorsal, q);
    }
    add_part("palm", HandPart::kPalm, render::kPalmPart, p.skin_rgb, m);
  }

  // --- webs ---

  // A thin sheet from a to b (both inside digits), `reach` [m] wide across the line (toward x_T
  // = (b − a) × z_H by `shift`), narrower in the middle: its free edge is a U.
  skin::Mesh web(const Vec3& a, const Vec3& b, double reach, double shift, double half_dorsal,
                 double half_palmar, const skin::WeightFn& weights) {
    Tube t;
    t.p_H_origin = a;
    const Vec3 y = (b - a).normalized();
    const Vec3 z = (Vec3::UnitZ() - Vec3::UnitZ().dot(y) * y).normalized();
    t.R_HT.col(0) = y.cross(z);
    t.R_HT.col(1) = y;
    t.R_HT.col(2) = z;
    const double len = (b - a).norm();
    auto st = [&](double s, double hx) {
      Station x;
      x.s = s;
      x.half_x = hx;
      x.half_dorsal = half_dorsal;
      x.half_palmar = half_palmar;
      x.shift_x = shift;
      x.shift_z = -0.25 * (half_dorsal + half_palmar);
      return x;
    };
    t.stations = {st(0.0, reach), st(0.5 * len, 0.75 * reach), st(len, reach)};
    t.dome_start = t.dome_end = 0.02 * W;
    skin::Mesh m;
    skin::sweep(t, 12, 0.004, 3, weights, &m);
    return m;
  }

  void finger_webs() {
    static constexpr const char* kNames[] = {"", "web_index_middle", "web_middle_ring",
                                             "web_ring_little"};
    for (int f = hand::kIndex; f < hand::kLittle; ++f) {
      const int g = f + 1;
      const double L1f = digit(f).length[1], L1g = digit(g).length[1];
      const Vec3 uf = digit(f).R_H_digit.col(1), ug = digit(g).R_H_digit.col(1);
      const Vec3 a = joint(f, 0) + 0.22 * L1f * uf;
      const Vec3 b = joint(g, 0) + 0.22 * L1g * ug;
      const Vec3 along = (uf + ug).normalized();
      const double L1 = 0.5 * (L1f + L1g);
      const int bf = phalanx_bone(f, 0), bg = phalanx_bone(g, 0);
      const Vec3 ab = b - a;
      auto weights = [=](double, const Vec3& q) {
        const double lambda = std::clamp((q - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
        const double level = (q - a).dot(along);  // distal positive
        const double w_palm = 1.0 - 0.75 * smoothstep(-0.2 * L1, 0.15 * L1, level);
        BoneWeights w;
        w.bone = {static_cast<std::uint8_t>(kPalmBone), static_cast<std::uint8_t>(bf),
                  static_cast<std::uint8_t>(bg)};
        w.weight = {static_cast<float>(w_palm), static_cast<float>((1 - w_palm) * (1 - lambda)),
                    static_cast<float>((1 - w_palm) * lambda)};
        return w;
      };
      // x_T = y × z points proximally here (fingers run along +y_H, a → b along +x_H).
      const skin::Mesh m = web(a, b, 0.20 * L1, 0.05 * L1, 0.05 * W, 0.07 * W, weights);
      add_part(kNames[f], HandPart::kWeb, render::kPalmPart, p.skin_rgb, m);
    }
  }

  void thumb_web() {
    const hand::DigitShape& t = digit(hand::kThumb);
    const hand::DigitShape& i = digit(hand::kIndex);
    const Vec3 a = joint(hand::kThumb, 1) + 0.15 * t.length[1] * t.R_H_digit.col(1);
    const Vec3 b = joint(hand::kIndex, 0) + 0.05 * i.length[1] * i.R_H_digit.col(1) -
                   0.09 * W * i.R_H_digit.col(0);
    const Vec3 ab = b - a;
    const double reach = 0.16 * W;
    const Vec3 y = ab.normalized();
    const Vec3 inward = y.cross(Vec3::UnitZ()).normalized();  // x_T: into the palm
    const int meta = kThumbMetacarpalBone, prox = phalanx_bone(hand::kThumb, 0);
    auto weights = [=](double, const Vec3& q) {
      const double lambda = std::clamp((q - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
      const double depth = std::clamp((q - a).dot(inward) / (2 * reach), 0.0, 1.0);
      const double w_palm = std::max(lambda, 0.7 * depth);
      BoneWeights w;
      w.bone = {static_cast<std::uint8_t>(kPalmBone), static_cast<std::uint8_t>(meta),
                static_cast<std::uint8_t>(prox)};
      w.weight = {static_cast<float>(w_palm), static_cast<float>(0.6 * (1 - w_palm)),
                  static_cast<float>(0.4 * (1 - w_palm))};
      return w;
    };
    const skin::Mesh m = web(a, b, reach, 0.9 * reach, 0.05 * W, 0.06 * W, weights);
    add_part("web_thumb_index", HandPart::kWeb, render::kPalmPart, p.skin_rgb, m);
  }

  // --- forearm and bracelet ---

  // The forearm's frame: along −y_H (toward the elbow), z dorsal.
  Tube arm_tube() const {
    Tube t;
    t.R_HT.col(0) = -Vec3::UnitX();
    t.R_HT.col(1) = -Vec3::UnitY();
    t.R_HT.col(2) = Vec3::UnitZ();
    return t;
  }
  // The forearm's cross-section s [m] from the wrist (flattened, widening toward the elbow).
  Station arm_station(double s, double grow = 0.0) const {
    Station x;
    x.s = s;
    const double d = std::max(s, 0.0);
    x.half_x = 0.33 * W + 0.07 * d + grow;
    x.half_dorsal = 0.18 * W + 0.05 * d + grow;
    x.half_palmar = 0.20 * W + 0.08 * d + grow;
    x.exponent = 0.85;
    return x;
  }

  void forearm() {
    if (p.forearm_length_m <= 0) return;
    Tube t = arm_tube();
    const double len = p.forearm_length_m;
    t.stations = {arm_station(-0.06 * W), arm_station(0.0), arm_station(0.5 * len), arm_station(len)};
    t.dome_start = 0.05 * W;
    t.dome_end = 0.01 * W;
    skin::Mesh m;
    skin::sweep(t, 28, 0.02, 4, [](double, const Vec3&) { return skin::rigid(kForearmBone); }, &m);
    add_part("forearm", HandPart::kForearm, render::kForearmPart, p.skin_rgb, m);
  }

  void bracelet() {
    if (p.bracelet_width_m <= 0) return;
    Tube t = arm_tube();
    const double c = p.bracelet_offset_m, h = 0.5 * p.bracelet_width_m;
    t.stations = {arm_station(c - h, p.bracelet_thickness_m), arm_station(c + h, p.bracelet_thickness_m)};
    skin::Mesh m;
    skin::sweep(t, 36, 0.01, 1, [](double, const Vec3&) { return skin::rigid(kForearmBone); }, &m);
    add_part("bracelet", HandPart::kBracelet, render::kBraceletPart, p.bracelet_rgb, m);
  }
};

}  // namespace

Status validate(const AnatomicalHandParams& p) {
  auto bad = [](const std::string& what) { return Status(Error{"anatomical hand: " + what}); };
  for (const auto* c : {&p.skin_rgb, &p.nail_rgb, &p.bracelet_rgb})
    for (float v : *c)
      if (!(v >= 0.f && v <= 1.f)) return bad("colours must be in [0, 1]");
  if (!(p.forearm_length_m >= 0 && p.forearm_length_m <= 0.5))
    return bad("forearm_length_m must be in [0, 0.5] m, got " + std::to_string(p.forearm_length_m));
  if (!(p.bracelet_width_m >= 0 && p.bracelet_width_m < 0.1))
    return bad("bracelet_width_m must be in [0, 0.1) m, got " + std::to_string(p.bracelet_width_m));
  if (!(p.bracelet_offset_m >= 0 && p.bracelet_offset_m < 0.1))
    return bad("bracelet_offset_m must be in [0, 0.1) m, got " + std::to_string(p.bracelet_offset_m));
  if (!(p.bracelet_thickness_m >= 0 && p.bracelet_thickness_m <= 0.01))
    return bad("bracelet_thickness_m must be in [0, 0.01] m");
  if (p.digit_slices < 8 || p.digit_slices > 64)
    return bad("digit_slices must be in 8..64, got " + std::to_string(p.digit_slices));
  return Ok{};
}

Result<AnatomicalHand> build_anatomical_hand(const hand::HandModel& model,
                                             const AnatomicalHandParams& params) {
  if (auto s = validate(params); !s) return s.error();
  // The rest skeleton in H with the right hand's numbers: a right-side copy, wrist at the origin.
  hand::HandModel right = model;
  right.side = hand::Side::kRight;
  Builder b{model, params, model.shape.dimensions.width, model.shape.dimensions.length,
            hand::forward_kinematics(right, hand::HandParams{}), {}, {}, {}};
  b.out.model = model;
  b.out.rest = hand_bone_frames(model, hand::HandParams{});
  b.palm();
  b.thumb_web();
  b.finger_webs();
  b.thumb();
  for (int f = hand::kIndex; f <= hand::kLittle; ++f) b.finger(f);
  for (int f = 0; f < hand::kFingerCount; ++f) b.nail(f);
  b.forearm();
  b.bracelet();
  return std::move(b.out);
}

}  // namespace spidar::sim
