#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "spidar/physics/mujoco_log.hpp"
#include "spidar/physics/passivity.hpp"
#include "spidar/physics/world.hpp"

namespace spidar::physics {
namespace {

std::string scene(const std::string& name) { return std::string(SPIDAR_SOURCE_DIR) + "/scenes/" + name; }

std::unique_ptr<World> load(const std::string& name, WorldParams params = {}) {
  auto w = World::Load(scene(name), params);
  EXPECT_TRUE(w.ok()) << (w.ok() ? "" : w.error().message);
  return std::move(w).value();
}

std::vector<Vec3> parked(int n = 8) {
  std::vector<Vec3> p;
  for (int i = 0; i < n; ++i) p.emplace_back(0.05 * i, 0.3, 0.3);  // in the air, out of the way
  return p;
}

TEST(World, BadSceneFilesGiveClearErrors) {
  auto missing = World::Load("/no/such/scene.xml");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().message,
            "/no/such/scene.xml: cannot open file (does it exist and is it readable?) (expected an "
            "MJCF .xml scene file)");

  const auto dir = std::filesystem::temp_directory_path();
  const auto bad = (dir / "spidar_bad_scene.xml").string();
  std::ofstream(bad) << "<mujoco><worldbody><geom type=\"box\" size=\"0.1 0.1\"/></worldbody></mujoco>";
  auto r = World::Load(bad);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find(bad + ": MuJoCo could not load the scene: "), std::string::npos)
      << r.error().message;
  EXPECT_NE(r.error().message.find("size"), std::string::npos) << r.error().message;  // MuJoCo's words

  const auto broken = (dir / "spidar_broken_scene.xml").string();
  std::ofstream(broken) << "<mujoco><worldbody><body></worldbody>";
  r = World::Load(broken);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find(broken + ":1: malformed XML: XML_ERROR_MISMATCHED_ELEMENT"),
            std::string::npos)
      << r.error().message;

  const auto empty = (dir / "spidar_no_worldbody.xml").string();
  std::ofstream(empty) << "<mujoco/>";
  r = World::Load(empty);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find(empty + ": no <worldbody> in <mujoco>"), std::string::npos)
      << r.error().message;
}

TEST(World, AddsOneProxyPerFingertipToAnyScene) {
  for (const char* s : {"blocks.xml", "rubiks_cube.xml"}) {
    auto w = load(s);
    EXPECT_EQ(w->proxies().size(), 8u);
    EXPECT_GE(w->body_id("proxy_7"), 0);
    EXPECT_DOUBLE_EQ(w->timestep(), 0.001);
  }
  WorldParams two;
  two.proxy.count = 2;
  EXPECT_EQ(load("blocks.xml", two)->proxies().size(), 2u);
}

// MuJoCo's preallocated memory and how much of it was used: after steps with the blocks resting on
// the table, some stack, constraint rows and contacts, within the scene's <size> (blocks.xml:
// njmax 1500, nconmax 300).
TEST(World, MemoryUseCountsWhatTheStepsUsedWithinTheScenesSizes) {
  auto w = load("blocks.xml");
  const World::MemoryUse before = w->memory_use();
  EXPECT_EQ(before.constraint_rows, 1500);
  EXPECT_EQ(before.contacts, 300);
  EXPECT_GT(before.stack_words, 0);
  const auto target = parked();
  w->place_proxies(target);
  std::vector<Vec3> v(8, Vec3::Zero());
  for (int k = 0; k < 200; ++k) w->step(target, v);
  const World::MemoryUse after = w->memory_use();
  EXPECT_GT(after.stack_words_max_used, 0);
  EXPECT_LE(after.stack_words_max_used, after.stack_words);
  EXPECT_GT(after.contacts_max_used, 0);  // the blocks on the table
  EXPECT_LE(after.contacts_max_used, after.contacts);
  EXPECT_GT(after.constraint_rows_max_used, 0);
  EXPECT_LE(after.constraint_rows_max_used, after.constraint_rows);
}

TEST(World, FreeProxyFollowsItsFingertipWithoutFalling) {
  auto w = load("blocks.xml");
  auto target = parked();
  w->place_proxies(target);
  std::vector<Vec3> v(8, Vec3::Zero());
  for (int k = 0; k < 500; ++k) {
    target[0] = Vec3(0.1 * std::sin(k * 0.004), 0.3, 0.3);
    w->step(target, v);
  }
  EXPECT_LT((w->proxies()[0].p_W - target[0]).norm(), 2e-3);  // follows within the coupling lag
  EXPECT_LT((w->proxies()[3].p_W - target[3]).norm(), 1e-6);  // gravity is compensated
  EXPECT_EQ(w->proxies()[0].plane_count, 0);
}

TEST(World, PressingAFixedBlockFeelsTheCouplingLaw) {
  auto w = load("blocks.xml");
  auto target = parked();
  // The fixed block's top is at z = 0.01; push the fingertip 6 mm into it.
  const Vec3 surface(0.12, 0.08, 0.01);
  const double r = w->params().proxy.radius, depth = 0.006;
  target[0] = surface + Vec3(0, 0, r + 0.01);
  w->place_proxies(target);
  target[0] = surface + Vec3(0, 0, r - depth);
  std::vector<Vec3> v(8, Vec3::Zero());
  for (int k = 0; k < 1000; ++k) w->step(target, v);
  const Vec3 f_user = -w->coupling_forces()[0];
  const double k = w->params().coupling.stiffness;
  // The user feels the spring stretched from the fingertip to the proxy resting on the block.
  const double stretch = w->proxies()[0].p_W.z() - target[0].z();
  EXPECT_NEAR(f_user.z(), k * stretch, 1e-6);
  EXPECT_NEAR(f_user.z(), k * depth, 0.05 * k * depth);  // the proxy barely sinks in
  EXPECT_LT(f_user.head<2>().norm(), 1e-3);
  ASSERT_GE(w->proxies()[0].plane_count, 1);
  EXPECT_GT(w->proxies()[0].planes[0].n_W.z(), 0.99);
  // The local model keeps the proxy on the block's surface.
  const Vec3 local = local_proxy_position(w->proxies()[0], 0.01);
  EXPECT_NEAR(local.z(), surface.z() + r, 5e-4);
}

/// Grasps the 100 g box with the given fingertip offsets (from the box centre), lifts it by 5 cm
/// in 1 s, holds 5 s, and returns the largest slip of the box relative to the fingertips [m].
double grasp_and_hold(const std::vector<Vec3>& offsets, double* lift) {
  WorldParams params;
  params.proxy.count = static_cast<int>(offsets.size());
  auto w = load("blocks.xml", params);
  const int box = w->body_id("box_100g");
  const Vec3 c0 = w->body_pose(box).p;
  std::vector<Vec3> target(offsets.size()), v(offsets.size(), Vec3::Zero());
  for (std::size_t i = 0; i < offsets.size(); ++i) target[i] = c0 + offsets[i] * 1.6;  // open
  w->place_proxies(target);
  const double dt = w->timestep();
  int steps = 0;
  auto run = [&](double seconds, auto&& script) {
    for (int k = 0; k < static_cast<int>(seconds / dt); ++k, ++steps) {
      script(k * dt);
      w->step(target, v);
    }
  };
  // Close (0.5 s) to 5 mm inside the faces, then lift 5 cm (1 s).
  run(0.5, [&](double t) {
    for (std::size_t i = 0; i < offsets.size(); ++i) {
      const Vec3 inside = offsets[i] - 0.005 * offsets[i].normalized();
      target[i] = c0 + offsets[i] * 1.6 + (inside - offsets[i] * 1.6) * std::min(1.0, t / 0.4);
    }
  });
  const std::vector<Vec3> closed = target;
  run(1.0, [&](double t) {
    for (std::size_t i = 0; i < offsets.size(); ++i) target[i] = closed[i] + Vec3(0, 0, 0.05 * t);
  });
  auto rel = [&] {
    Vec3 mid = Vec3::Zero();
    for (const auto& p : w->proxies()) mid += p.p_W;
    return Vec3(w->body_pose(box).p - mid / static_cast<double>(offsets.size()));
  };
  const Vec3 rel0 = rel();
  double slip = 0;
  run(5.0, [&](double) { slip = std::max(slip, (rel() - rel0).norm()); });
  *lift = w->body_pose(box).p.z() - c0.z();
  return slip;
}

TEST(World, TwoFingerPinchHoldsA100gBoxForFiveSeconds) {
  double lift = 0;
  const double slip = grasp_and_hold({Vec3(-0.028, 0, 0), Vec3(0.028, 0, 0)}, &lift);
  RecordProperty("pinch_slip_mm", std::to_string(slip * 1e3));
  EXPECT_LT(slip, 1e-3);
  EXPECT_GT(lift, 0.045);
}

TEST(World, FourFingerGraspHoldsA100gBoxForFiveSeconds) {
  double lift = 0;
  const double slip = grasp_and_hold(
      {Vec3(0, -0.028, 0), Vec3(-0.012, 0.028, 0.008), Vec3(0, 0.028, -0.004), Vec3(0.012, 0.028, 0.008)},
      &lift);
  RecordProperty("grasp_slip_mm", std::to_string(slip * 1e3));
  EXPECT_LT(slip, 1e-3);
  EXPECT_GT(lift, 0.045);
}

TEST(World, SnapshotListsVisibleShapesWithColoursAndMeshes) {
  auto w = load("rubiks_cube.xml");
  SceneSnapshot snap;
  w->snapshot(snap);
  int meshes = 0, white = 0;
  for (const auto& s : snap.shapes) {
    meshes += s.type == Shape::Type::kMesh;
    white += s.rgba[0] > 0.9f && s.rgba[1] > 0.9f && s.rgba[2] > 0.9f;
  }
  EXPECT_EQ(meshes, 26);  // cubelets
  EXPECT_EQ(white, 9);    // the U face's stickers
  ASSERT_TRUE(snap.meshes);
  ASSERT_EQ(snap.meshes->size(), 1u);
  EXPECT_GT((*snap.meshes)[0].faces.size(), 30u);
  // Storage is reused: a second snapshot does not grow.
  const auto n = snap.shapes.size();
  w->snapshot(snap);
  EXPECT_EQ(snap.shapes.size(), n);
}

TEST(Passivity, ObserverAndControllerOnAKnownPort) {
  // A spring port (F = −k x) is passive: over a cycle the absorbed energy returns to ~0, ≥ 0.
  PassivityPort spring(false);
  const double dt = 1e-3, k = 500;
  for (int i = 0; i < 2000; ++i) {
    const double t = i * dt, x = 0.01 * std::sin(10 * t), v = 0.1 * std::cos(10 * t);
    spring.step(Vec3(-k * x, 0, 0), Vec3(v, 0, 0), dt);
  }
  EXPECT_GE(spring.stats().min_energy, -1e-4);
  // A negative damper (F = +b v) is active: the observer sees it; the controller cancels it.
  PassivityPort observe(false), control(true);
  for (int i = 0; i < 1000; ++i) {
    const Vec3 v(0.2 * std::cos(i * 0.01), 0, 0);
    observe.step(3.0 * v, v, dt);
    const Vec3 f = control.step(3.0 * v, v, dt);
    EXPECT_LE(f.dot(v), 3.0 * v.squaredNorm() + 1e-12);
  }
  EXPECT_LT(observe.stats().min_energy, -0.05);
  EXPECT_GE(control.stats().min_energy, -1e-9);
  EXPECT_GT(control.stats().active_steps, 0u);
}

// MuJoCo 2.2.2 warns through mju_user_warning; without our handler it prints and appends to
// MUJOCO_LOG.TXT in the working directory. A proxy placed at 1e20 m makes qpos "huge" (above
// mjMAXVAL): the next step warns (bad_qpos) and resets the data.
TEST(World, MujocoWarningsAreCountedInTheProcessNotWrittenToTheWorkingDirectory) {
  namespace fs = std::filesystem;
  const fs::path cwd = fs::current_path();
  const fs::path dir = fs::temp_directory_path() / ("spidar_mujoco_log_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  fs::current_path(dir);
  {
    auto w = load("blocks.xml");
    const MujocoWarnings before = mujoco_warnings();
    EXPECT_EQ(w->warning_total(), 0);
    std::vector<Vec3> p = parked();
    p[0] = Vec3(1e20, 0, 0);
    w->place_proxies(p);
    w->step(parked(), {});
    const MujocoWarnings after = mujoco_warnings();
    EXPECT_GT(after.count, before.count);
    ASSERT_FALSE(after.messages.empty());
    EXPECT_NE(after.messages.back().find("QPOS"), std::string::npos) << after.messages.back();
    EXPECT_LE(after.messages.size(), kMujocoWarningsKept);
    EXPECT_GE(w->warning_total(), 1);
    bool bad_qpos = false;
    for (const auto& k : w->warning_counts()) bad_qpos = bad_qpos || (k.kind == "bad_qpos" && k.count >= 1);
    EXPECT_TRUE(bad_qpos);
    // The world goes on after MuJoCo's reset.
    w->step(parked(), {});
    EXPECT_TRUE(w->proxies()[0].p_W.allFinite());
  }
  const bool log_written = fs::exists(dir / "MUJOCO_LOG.TXT");
  fs::current_path(cwd);
  fs::remove_all(dir);
  EXPECT_FALSE(log_written) << "MuJoCo wrote MUJOCO_LOG.TXT into the working directory";
}

}  // namespace
}  // namespace spidar::physics
