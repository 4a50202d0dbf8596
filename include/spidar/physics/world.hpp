#pragma once
/// The virtual world: a MuJoCo 2.2.2 model loaded from MJCF, with one proxy sphere per device
/// fingertip added to whatever scene it is given. Each step pulls every proxy toward its measured
/// fingertip through the virtual coupling, applying the forces between mj_step1 and mj_step2 (so
/// they use the current state, not the previous step's).
///
/// MuJoCo stays inside this module: its types appear here only as opaque pointers.
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "spidar/core/result.hpp"
#include "spidar/core/scene_snapshot.hpp"
#include "spidar/physics/coupling.hpp"
#include "spidar/physics/mjcf_proxies.hpp"

struct mjModel_;
struct mjData_;

namespace spidar::physics {

struct WorldParams {
  ProxyParams proxy;
  CouplingParams coupling;
};

/// A hook run inside each step, between mj_step1 and mj_step2 (e.g. the cube's detents).
using StepHook = std::function<void(const mjModel_* m, mjData_* d)>;

class World {
 public:
  /// Loads `scene_path`, adding `params.proxy.count` proxies. Errors name the file and quote
  /// MuJoCo's message.
  static Result<std::unique_ptr<World>> Load(const std::string& scene_path,
                                             const WorldParams& params = {});
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  /// One physics step toward the fingertip targets (positions [m], velocities [m/s], world).
  void step(std::span<const Vec3> p_W_target, std::span<const Vec3> v_W_target);
  /// Teleports the proxies to the targets at rest (before the first step, or after a reset).
  void place_proxies(std::span<const Vec3> p_W_target);
  /// Force each proxy's coupling applied in the last step [N] (the user feels its negative).
  std::span<const Vec3> coupling_forces() const { return coupling_force_; }
  /// Proxy states after the last step, with their contact planes.
  std::span<const ProxyState> proxies() const { return proxies_; }

  void add_step_hook(StepHook hook) { hooks_.push_back(std::move(hook)); }
  /// A hook run after mj_step2, when the step's contacts and constraint forces are consistent
  /// (mj_contactForce is valid); what it changes in the model takes effect in the next step.
  void add_post_step_hook(StepHook hook) { post_hooks_.push_back(std::move(hook)); }
  double time() const;
  double timestep() const;
  int contact_count() const;
  /// MuJoCo's warnings in this world's data (mjData::warning[]: too many contacts, a bad number
  /// in qpos/qvel/qacc that made MuJoCo reset the data, …) since it was made or last reset; only
  /// the kinds that occurred. Read it while the world is not stepping. The messages themselves
  /// are in mujoco_warnings() (mujoco_log.hpp).
  struct WarningCount {
    std::string kind;  ///< "contact_full", "bad_qacc", …
    int count = 0;
  };
  std::vector<WarningCount> warning_counts() const;
  /// The sum of warning_counts().
  int warning_total() const;
  /// How much of MuJoCo's preallocated memory the steps so far used: its stack (`<size nstack>`,
  /// 8-byte words; by default MuJoCo 2.2 sizes it from njmax², 48.7 M words for njmax 3000, but
  /// touches only what it uses) and its constraint rows and contacts (`<size njmax nconmax>`).
  /// Read it while the world is not stepping.
  struct MemoryUse {
    long stack_words = 0, stack_words_max_used = 0;
    int constraint_rows = 0, constraint_rows_max_used = 0;
    int contacts = 0, contacts_max_used = 0;
  };
  MemoryUse memory_use() const;
  const WorldParams& params() const { return params_; }
  const std::string& scene_path() const { return scene_path_; }

  /// Fills a snapshot (reusing its storage): every visible geom with its pose and colour.
  /// Without `include_proxies` the fingertip proxies are left out (a mixed-reality view shows the
  /// real fingers instead).
  void snapshot(SceneSnapshot& out, bool include_proxies = true) const;

  /// Body/joint lookup for scene-specific code (−1 if absent).
  int body_id(const std::string& name) const;
  /// World pose of a body.
  Pose body_pose(int body) const;
  /// Raw MuJoCo access for code inside the physics module.
  const mjModel_* model() const { return model_; }
  /// Mutable model, for mechanisms of the physics module that switch constraints at run time.
  mjModel_* mutable_model() { return model_; }
  mjData_* data() { return data_; }
  const mjData_* data() const { return data_; }

 private:
  World() = default;
  void update_proxy_states();

  WorldParams params_;
  std::string scene_path_;
  mjModel_* model_ = nullptr;
  mjData_* data_ = nullptr;
  std::vector<int> proxy_body_, proxy_geom_, proxy_qpos_, proxy_dof_;
  std::vector<Vec3> proxy_origin_;  ///< body position at qpos = 0 [m]
  std::vector<Vec3> coupling_force_;
  std::vector<ProxyState> proxies_;
  std::vector<StepHook> hooks_, post_hooks_;
  std::shared_ptr<const std::vector<MeshData>> meshes_;
};

}  // namespace spidar::physics
