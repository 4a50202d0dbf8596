// The simulated user's anatomical hand: a valid closed mesh, skinning that reproduces the rest
// mesh, joints that move only their own digit, fingertips on the skeleton's, and cheap posing.
#include <gtest/gtest.h>

#include <chrono>
#include <iostream>
#include <map>
#include <random>

#include "allocation_counter.hpp"
#include "spidar/hand/forearm.hpp"
#include "spidar/hand/joint_limits.hpp"
#include "spidar/hand/kinematics.hpp"
#include "spidar/hand/rotation_vector.hpp"
#include "spidar/render/hand_skin.hpp"
#include "spidar/sim/anatomical_hand.hpp"

namespace spidar::sim {
namespace {

hand::HandModel user_model(hand::Side side) {
  hand::HandDimensions dims;  // the test users' hands (tests/render/synthetic_hands.hpp)
  dims.length = 0.182;
  dims.width = 0.081;
  return hand::make_hand_model(side, dims).value();
}

AnatomicalHand build(hand::Side side, const AnatomicalHandParams& p = {}) {
  auto r = build_anatomical_hand(user_model(side), p);
  EXPECT_TRUE(r.ok());
  return std::move(r).value();
}

// Posed vertices of every part (world), in part order.
std::vector<std::vector<float>> posed(const AnatomicalHand& h, const hand::HandParams& q) {
  std::vector<MeshData> meshes = part_meshes(h);
  pose_anatomical_hand(h, q, meshes);
  std::vector<std::vector<float>> out;
  for (auto& m : meshes) out.push_back(m.vertices);
  return out;
}

const SkinnedPart& part(const AnatomicalHand& h, const std::string& name) {
  for (const auto& p : h.parts)
    if (p.name == name) return p;
  ADD_FAILURE() << "no part " << name;
  return h.parts.front();
}
std::size_t part_index(const AnatomicalHand& h, const std::string& name) {
  return static_cast<std::size_t>(&part(h, name) - h.parts.data());
}

Vec3 vertex(const std::vector<float>& v, std::size_t i) {
  return Vec3(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
}

hand::HandParams some_pose(std::mt19937& rng, const hand::HandModel& m) {
  hand::HandParams q;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = hand::kThumbCmcFlexion; i < hand::kParamCount; ++i) {
    const double lo = std::max(m.limits.lower[i], -1.0), hi = std::min(m.limits.upper[i], 1.2);
    q[i] = lo + (hi - lo) * u(rng);
  }
  q.set_wrist(Vec3(0.1 * u(rng), 0.1 * u(rng), 0.05), Vec3(0.3 * u(rng), -0.2, 1.0 + u(rng)));
  q.little_independent = true;
  q.set_little(Vec3(q[hand::kRingMcpFlexion] + 0.1, q[hand::kRingMcpAbduction], q[hand::kRingDip] + 0.1));
  return q;
}

TEST(AnatomicalHand, PartsAreClosedOutwardMeshes) {
  for (auto side : {hand::Side::kLeft, hand::Side::kRight}) {
    const AnatomicalHand h = build(side);
    std::size_t vertices = 0;
    int fingers[8] = {};
    for (const SkinnedPart& p : h.parts) {
      SCOPED_TRACE(p.name);
      vertices += p.p_H_rest.size();
      ++fingers[p.finger + 1];
      ASSERT_EQ(p.n_H_rest.size(), p.p_H_rest.size());
      ASSERT_EQ(p.weights.size(), p.p_H_rest.size());
      ASSERT_EQ(p.faces.size() % 3, 0u);
      ASSERT_GT(p.faces.size(), 0u);
      for (std::size_t i = 0; i < p.p_H_rest.size(); ++i) {
        ASSERT_TRUE(p.p_H_rest[i].allFinite());
        ASSERT_NEAR(p.n_H_rest[i].norm(), 1.0, 1e-4);
        float sum = 0;
        for (int k = 0; k < 3; ++k) {
          sum += p.weights[i].weight[k];
          ASSERT_GE(p.weights[i].weight[k], 0.f);
          ASSERT_LT(p.weights[i].bone[k], kHandBoneCount);
        }
        ASSERT_NEAR(sum, 1.f, 1e-5);
      }
      // Closed and consistently wound: every directed edge once, its reverse once.
      std::map<std::pair<int, int>, int> edges;
      const int n = static_cast<int>(p.p_H_rest.size());
      for (std::size_t f = 0; f < p.faces.size(); f += 3)
        for (int k = 0; k < 3; ++k) {
          const int a = p.faces[f + k], b = p.faces[f + (k + 1) % 3];
          ASSERT_TRUE(a >= 0 && a < n && b >= 0 && b < n);
          ++edges[{a, b}];
        }
      for (const auto& [e, count] : edges) {
        ASSERT_EQ(count, 1) << e.first << "→" << e.second;
        ASSERT_EQ(edges.count({e.second, e.first}), 1u) << "open edge " << e.first << "→" << e.second;
      }
      // Outward: positive enclosed volume in world (the left hand's mirror included).
      hand::HandParams q;
      const auto v = posed(h, q)[static_cast<std::size_t>(&p - h.parts.data())];
      double volume = 0;
      for (std::size_t f = 0; f < p.faces.size(); f += 3)
        volume += vertex(v, p.faces[f]).dot(vertex(v, p.faces[f + 1]).cross(vertex(v, p.faces[f + 2]))) / 6;
      EXPECT_GT(volume, 0.0);
    }
    // Parts: palm and webs (palm id), five digits, five nails, forearm, bracelet.
    EXPECT_EQ(fingers[0], 5);                            // palm + 4 webs
    for (int f = 0; f < 5; ++f) EXPECT_EQ(fingers[f + 1], 2) << f;  // digit + nail
    EXPECT_EQ(fingers[render::kBraceletPart + 1], 1);
    EXPECT_EQ(fingers[render::kForearmPart + 1], 1);
    EXPECT_GT(vertices, 2000u);
    EXPECT_LT(vertices, 8000u);
    if (side == hand::Side::kRight) std::cout << "anatomical hand: " << vertices << " vertices\n";
  }
}

TEST(AnatomicalHand, RestPoseReproducesTheRestMesh) {
  for (auto side : {hand::Side::kLeft, hand::Side::kRight}) {
    const AnatomicalHand h = build(side);
    const auto v = posed(h, hand::HandParams{});
    const float mirror = side == hand::Side::kLeft ? -1.f : 1.f;
    for (std::size_t i = 0; i < h.parts.size(); ++i)
      for (std::size_t j = 0; j < h.parts[i].p_H_rest.size(); ++j) {
        Eigen::Vector3f e = h.parts[i].p_H_rest[j];
        e.x() *= mirror;
        ASSERT_LT((vertex(v[i], j).cast<float>() - e).norm(), 1e-6f) << h.parts[i].name << " " << j;
      }
  }
}

// How far each part's vertices move between two poses: max per part [m].
std::vector<double> motion(const AnatomicalHand& h, const hand::HandParams& a, const hand::HandParams& b) {
  const auto va = posed(h, a), vb = posed(h, b);
  std::vector<double> out;
  for (std::size_t i = 0; i < va.size(); ++i) {
    double m = 0;
    for (std::size_t j = 0; j < va[i].size() / 3; ++j) m = std::max(m, (vertex(va[i], j) - vertex(vb[i], j)).norm());
    out.push_back(m);
  }
  return out;
}

TEST(AnatomicalHand, AJointMovesOnlyItsDigit) {
  for (auto side : {hand::Side::kLeft, hand::Side::kRight}) {
    const AnatomicalHand h = build(side);
    hand::HandParams rest;
    rest.set_wrist(Vec3(0.05, -0.02, 0.03), Vec3(0.2, -0.1, 0.9));

    // Index DIP (PIP coupled): the index and its nail move, nothing else; the proximal phalanx
    // and the base of the digit stay.
    hand::HandParams bent = rest;
    bent[hand::kIndexDip] = 0.9;
    auto m = motion(h, rest, bent);
    for (std::size_t i = 0; i < h.parts.size(); ++i) {
      const bool index = h.parts[i].name == "index" || h.parts[i].name == "index_nail";
      if (index) {
        EXPECT_GT(m[i], 0.005) << h.parts[i].name;
      } else {
        EXPECT_LT(m[i], 1e-6) << h.parts[i].name;
      }
    }
    {
      const SkinnedPart& idx = part(h, "index");
      const auto va = posed(h, rest)[part_index(h, "index")], vb = posed(h, bent)[part_index(h, "index")];
      for (std::size_t j = 0; j < idx.weights.size(); ++j) {
        bool on_moving = false;
        for (int k = 0; k < 3; ++k)
          if (idx.weights[j].weight[k] > 0 && idx.weights[j].bone[k] != kPalmBone &&
              idx.weights[j].bone[k] != phalanx_bone(hand::kIndex, 0))
            on_moving = true;
        if (!on_moving) {
          EXPECT_LT((vertex(va, j) - vertex(vb, j)).norm(), 1e-6) << j;
        }
      }
    }

    // Index MCP: the index, its nail and the index-middle web move (the web only in part); the
    // palm, the other digits and the other webs stay.
    bent = rest;
    bent[hand::kIndexMcpFlexion] = 1.0;
    m = motion(h, rest, bent);
    for (std::size_t i = 0; i < h.parts.size(); ++i) {
      const std::string& n = h.parts[i].name;
      if (n == "index" || n == "index_nail" || n == "web_index_middle") {
        EXPECT_GT(m[i], 0.003) << n;
      } else {
        EXPECT_LT(m[i], 1e-6) << n;
      }
    }

    // The independent little finger: only the little finger, its nail and its web move.
    bent = rest;
    bent.little_independent = true;
    bent.set_little(Vec3(0.8, 0.1, 0.6));
    m = motion(h, rest, bent);
    for (std::size_t i = 0; i < h.parts.size(); ++i) {
      const std::string& n = h.parts[i].name;
      if (n == "little" || n == "little_nail" || n == "web_ring_little") {
        EXPECT_GT(m[i], 0.001) << n;  // the web only at its little-finger end
      } else {
        EXPECT_LT(m[i], 1e-6) << n;
      }
    }
  }
}

// A bending wrist: given where the forearm points, the forearm and its bracelet turn about the
// wrist onto that direction, and nothing of the hand moves.
TEST(AnatomicalHand, TheForearmAndBraceletTurnAboutTheWristOntoTheElbow) {
  for (auto side : {hand::Side::kLeft, hand::Side::kRight}) {
    const AnatomicalHand h = build(side);
    hand::HandParams q;
    const Vec3 wrist(0.05, -0.02, 0.3);
    q.set_wrist(wrist, Vec3(0.2, -0.1, 0.9));
    const Mat3 R = hand::rotation_from_vector(q.r_W_hand());
    const Vec3 d = Eigen::AngleAxisd(0.8, R.col(0)) * Vec3(-R.col(1));
    std::vector<MeshData> straight = part_meshes(h), bent = part_meshes(h);
    pose_anatomical_hand(h, q, straight);
    pose_anatomical_hand(h, q, bent, &d);
    const Mat3 B = hand::wrist_bend(R, d);
    for (std::size_t i = 0; i < h.parts.size(); ++i) {
      const bool arm = h.parts[i].kind == HandPart::kForearm || h.parts[i].kind == HandPart::kBracelet;
      double worst = 0;
      for (std::size_t j = 0; j + 2 < straight[i].vertices.size(); j += 3) {
        const Vec3 a(straight[i].vertices[j], straight[i].vertices[j + 1], straight[i].vertices[j + 2]);
        const Vec3 b(bent[i].vertices[j], bent[i].vertices[j + 1], bent[i].vertices[j + 2]);
        const Vec3 expected = arm ? Vec3(wrist + B * (a - wrist)) : a;
        worst = std::max(worst, (b - expected).norm());
      }
      EXPECT_LT(worst, 2e-6) << h.parts[i].name;  // float vertices
    }
  }
}

TEST(AnatomicalHand, FingertipsSitOnTheSkeletonsFingertips) {
  std::mt19937 rng(7);
  for (auto side : {hand::Side::kLeft, hand::Side::kRight}) {
    const AnatomicalHand h = build(side);
    for (int trial = 0; trial < 20; ++trial) {
      const hand::HandParams q = some_pose(rng, h.model);
      const hand::HandPoints fk = hand::forward_kinematics(h.model, q);
      const auto v = posed(h, q);
      for (int f = 0; f < hand::kFingerCount; ++f) {
        SCOPED_TRACE(::testing::Message() << "finger " << f << " trial " << trial);
        const auto& digit = v[static_cast<std::size_t>(h.tip_part[f])];
        const Vec3 pole = vertex(digit, static_cast<std::size_t>(h.tip_vertex[f]));
        // The skin's tip is just beyond the end of the distal bone.
        EXPECT_LT((pole - fk.p_W_joint[hand::joint_index(f, 3)]).norm(), 0.002);
        if (f >= hand::kFingertipCount) continue;
        // The device's cap centre is inside the fingertip, under its surface: a few mm from the
        // nearest skin vertex, not outside (farther than the pad's half depth).
        const Vec3 cap = fk.p_W_fingertip[f];
        double nearest = 1e9;
        for (std::size_t j = 0; j < digit.size() / 3; ++j) nearest = std::min(nearest, (vertex(digit, j) - cap).norm());
        EXPECT_GT(nearest, 0.003);
        EXPECT_LT(nearest, 0.010);
      }
    }
  }
}

TEST(AnatomicalHand, PosingIsCheapAndDoesNotAllocate) {
  const AnatomicalHand h = build(hand::Side::kRight);
  std::vector<MeshData> meshes = part_meshes(h);
  std::mt19937 rng(3);
  const hand::HandParams q = some_pose(rng, h.model);
  pose_anatomical_hand(h, q, meshes);
  namespace alloc = ::spidar::testing::allocations;
  if (alloc::available()) {
    alloc::mark_this_thread();
    alloc::start();
    pose_anatomical_hand(h, q, meshes);
    alloc::stop();
    EXPECT_EQ(alloc::count(), 0);
  }
  EXPECT_EQ(meshes[0].version, alloc::available() ? 2u : 1u);
  // Timing is reported, not asserted (sanitizer builds run slower; timing lives in benchmarks).
  constexpr int kRuns = 200;
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < kRuns; ++i) pose_anatomical_hand(h, q, meshes);
  const double us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count() / kRuns;
  std::cout << "anatomical hand: skinning " << us << " us per hand per pose\n";
}

TEST(AnatomicalHand, RejectsBadParams) {
  AnatomicalHandParams p;
  p.forearm_length_m = -1;
  auto r = build_anatomical_hand(user_model(hand::Side::kRight), p);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("forearm_length_m"), std::string::npos);
  p = {};
  p.digit_slices = 3;
  EXPECT_FALSE(validate(p).ok());
}

}  // namespace
}  // namespace spidar::sim
