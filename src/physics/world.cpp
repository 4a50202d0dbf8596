#include "spidar/physics/world.hpp"

#include <algorithm>

#include <mujoco/mujoco.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <sstream>

#include "spidar/core/file_read.hpp"
#include "spidar/physics/mujoco_log.hpp"

#include "model_numbers.hpp"

namespace spidar::physics {
namespace {

/// MuJoCo's model compiled from MJCF `text` staged in a virtual file system under the scene's own
/// file name, so relative assets and includes still resolve against the scene's directory. Null
/// with MuJoCo's message in `err` on failure.
mjModel* load_from_memory(const std::string& scene_path, const std::string& text,
                          std::string& err) {
  namespace fs = std::filesystem;
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  const std::string name = fs::path(scene_path).filename().string();
  if (mj_makeEmptyFileVFS(vfs.get(), name.c_str(), static_cast<int>(text.size())) != 0) {
    err = "could not stage the scene in MuJoCo's virtual file system";
    return nullptr;
  }
  const int idx = mj_findFileVFS(vfs.get(), name.c_str());
  std::memcpy(vfs->filedata[idx], text.data(), text.size());
  char buf[1024] = "";
  mjModel* m = mj_loadXML(scene_path.c_str(), vfs.get(), buf, sizeof(buf));
  mj_deleteVFS(vfs.get());
  err = buf;
  return m;
}

/// Physics steps in real time beside the servo loop: a step longer than this makes the coupling
/// a spring sampled too slowly to be stable, one shorter cannot be computed in real time.
/// Measured (demo, a 4 cm box held and twisted, seed 1): at 1 and 2 ms the simulated user's caps
/// stay within 0.63 mm of its fingers and the fit scores IoU 0.86; at 3 ms the fingertip contacts
/// no longer settle, the caps swing up to 9.1 mm away (5 ms: 8.7 mm) and IoU falls to 0.72–0.77.
/// 2 ms is also MuJoCo's default time step.
constexpr double kMinTimestep = 1e-5;  // [s]
constexpr double kMaxTimestep = 0.002;  // [s]

}  // namespace

Result<std::unique_ptr<World>> World::Load(const std::string& scene_path, const WorldParams& params) {
  install_mujoco_warning_handler();  // before MuJoCo's compiler can warn
  if (params.proxy.count < 0 || params.proxy.count > 16 || !(params.proxy.radius > 0) ||
      !(params.proxy.mass > 0)) {
    return Error{scene_path + ": bad proxy parameters (count 0..16, radius > 0, mass > 0)"};
  }
  std::string original;
  try {
    original = core::read_file_bounded(scene_path, kMaxSceneFileBytes, "a scene file");
  } catch (const core::FileError& e) {
    return Error{std::string(e.what()) + " (expected an MJCF .xml scene file)"};
  }
  auto text = inject_proxies(original, params.proxy, scene_path);
  if (!text) return text.error();

  std::string err;
  mjModel* m = load_from_memory(scene_path, *text, err);
  if (!m) {
    // MuJoCo's line numbers are of the re-printed text: quote its words about the user's own file
    // when that fails alone, and say so when only the proxies made it fail (a name clash).
    std::string err_original;
    if (mjModel* alone = load_from_memory(scene_path, original, err_original)) {
      mj_deleteModel(alone);
      return Error{scene_path + ": MuJoCo could not load the scene with the fingertip proxies added "
                                "(a name clash with proxy_N?): " + err};
    }
    return Error{scene_path + ": MuJoCo could not load the scene: " + err_original};
  }
  if (const std::string bad = first_non_finite_number(m); !bad.empty()) {
    mj_deleteModel(m);
    return Error{scene_path + ": the compiled scene has a non-finite number in " + bad +
                 " (a nan or inf in the MJCF?); expected finite numbers"};
  }
  if (const std::string bad = first_implausible_number(m); !bad.empty()) {
    mj_deleteModel(m);
    return Error{scene_path + ": the compiled scene's " + bad};
  }
  const double dt = m->opt.timestep;
  if (!(dt >= kMinTimestep && dt <= kMaxTimestep)) {
    mj_deleteModel(m);
    std::ostringstream os;
    os << scene_path << ": <option timestep=\"" << dt << "\"> is out of range; expected "
       << kMinTimestep << " s <= timestep <= " << kMaxTimestep
       << " s (the physics renders the fingertips' contacts at 1/timestep beside the 1 kHz servo "
          "loop; with longer steps they do not settle)";
    return Error{os.str()};
  }

  std::unique_ptr<World> w(new World());
  w->params_ = params;
  w->scene_path_ = scene_path;
  w->model_ = m;
  w->data_ = mj_makeData(m);
  for (int i = 0; i < params.proxy.count; ++i) {
    const std::string b = "proxy_" + std::to_string(i);
    const int body = mj_name2id(m, mjOBJ_BODY, b.c_str());
    const int geom = mj_name2id(m, mjOBJ_GEOM, (b + "_geom").c_str());
    const int joint = mj_name2id(m, mjOBJ_JOINT, (b + "_x").c_str());
    if (body < 0 || geom < 0 || joint < 0) {
      return Error{scene_path + ": proxy " + b + " missing after loading (name clash in the scene?)"};
    }
    w->proxy_body_.push_back(body);
    w->proxy_geom_.push_back(geom);
    w->proxy_qpos_.push_back(m->jnt_qposadr[joint]);
    w->proxy_dof_.push_back(m->jnt_dofadr[joint]);
    w->proxy_origin_.emplace_back(m->body_pos[3 * body], m->body_pos[3 * body + 1],
                                  m->body_pos[3 * body + 2]);
  }
  w->coupling_force_.assign(params.proxy.count, Vec3::Zero());
  w->proxies_.assign(params.proxy.count, ProxyState{});
  mj_forward(m, w->data_);
  w->update_proxy_states();

  // Meshes for snapshots, once.
  auto meshes = std::make_shared<std::vector<MeshData>>();
  for (int k = 0; k < m->nmesh; ++k) {
    MeshData md;
    const char* mname = mj_id2name(m, mjOBJ_MESH, k);
    md.name = mname ? mname : "";
    const int v0 = m->mesh_vertadr[k], nv = m->mesh_vertnum[k];
    for (int v = 0; v < 3 * nv; ++v) md.vertices.push_back(m->mesh_vert[3 * v0 + v]);
    const int f0 = m->mesh_faceadr[k], nf = m->mesh_facenum[k];
    for (int f = 0; f < 3 * nf; ++f) md.faces.push_back(m->mesh_face[3 * f0 + f]);
    meshes->push_back(std::move(md));
  }
  w->meshes_ = meshes;
  return w;
}

World::~World() {
  if (data_) mj_deleteData(data_);
  if (model_) mj_deleteModel(model_);
}

double World::time() const { return data_->time; }
double World::timestep() const { return model_->opt.timestep; }
int World::contact_count() const { return data_->ncon; }

World::MemoryUse World::memory_use() const {
  MemoryUse u;
  u.stack_words = model_->nstack;
  u.stack_words_max_used = data_->maxuse_stack;
  u.constraint_rows = model_->njmax;
  u.constraint_rows_max_used = data_->maxuse_efc;
  u.contacts = model_->nconmax;
  u.contacts_max_used = data_->maxuse_con;
  return u;
}

std::vector<World::WarningCount> World::warning_counts() const {
  static constexpr const char* kKinds[mjNWARNING] = {"inertia",  "contact_full", "constraint_full",
                                                     "vgeom_full", "bad_qpos", "bad_qvel",
                                                     "bad_qacc", "bad_ctrl"};
  std::vector<WarningCount> out;
  for (int k = 0; k < mjNWARNING; ++k) {
    if (data_->warning[k].number > 0) out.push_back({kKinds[k], data_->warning[k].number});
  }
  return out;
}

int World::warning_total() const {
  int n = 0;
  for (int k = 0; k < mjNWARNING; ++k) n += data_->warning[k].number;
  return n;
}

int World::body_id(const std::string& name) const {
  return mj_name2id(model_, mjOBJ_BODY, name.c_str());
}

Pose World::body_pose(int b) const {
  Pose X;
  X.p = Vec3(data_->xpos[3 * b], data_->xpos[3 * b + 1], data_->xpos[3 * b + 2]);
  X.R = Quat(data_->xquat[4 * b], data_->xquat[4 * b + 1], data_->xquat[4 * b + 2],
             data_->xquat[4 * b + 3]);
  return X;
}

void World::place_proxies(std::span<const Vec3> p_W) {
  for (std::size_t i = 0; i < proxy_body_.size() && i < p_W.size(); ++i) {
    double* q = data_->qpos + proxy_qpos_[i];
    const Vec3 d = p_W[i] - proxy_origin_[i];  // slide joints measure from the body's origin
    q[0] = d.x(), q[1] = d.y(), q[2] = d.z();
    for (int k = 0; k < 3; ++k) data_->qvel[proxy_dof_[i] + k] = 0;
  }
  mj_forward(model_, data_);
  update_proxy_states();
}

void World::step(std::span<const Vec3> p_W_target, std::span<const Vec3> v_W_target) {
  mj_step1(model_, data_);
  const double g = std::abs(model_->opt.gravity[2]);
  for (std::size_t i = 0; i < proxy_body_.size(); ++i) {
    const int b = proxy_body_[i];
    const double* q = data_->qpos + proxy_qpos_[i];
    const double* v = data_->qvel + proxy_dof_[i];  // slide joints along world x, y, z
    const Vec3 p_P = proxy_origin_[i] + Vec3(q[0], q[1], q[2]), v_P(v[0], v[1], v[2]);
    Vec3 f = Vec3::Zero();
    if (i < p_W_target.size() && p_W_target[i].allFinite()) {
      const Vec3 v_T = i < v_W_target.size() && v_W_target[i].allFinite() ? v_W_target[i] : Vec3::Zero();
      f = coupling_force(params_.coupling, p_W_target[i], v_T, p_P, v_P);
    }
    coupling_force_[i] = f;
    double* xf = data_->xfrc_applied + 6 * b;
    xf[0] = f.x(), xf[1] = f.y(), xf[2] = f.z() + model_->body_mass[b] * g;  // gravity compensated
  }
  for (auto& hook : hooks_) hook(model_, data_);
  mj_step2(model_, data_);
  for (auto& hook : post_hooks_) hook(model_, data_);
  update_proxy_states();
}

void World::update_proxy_states() {
  const double r = params_.proxy.radius;
  for (std::size_t i = 0; i < proxy_body_.size(); ++i) {
    ProxyState& s = proxies_[i];
    const double* q = data_->qpos + proxy_qpos_[i];
    const double* v = data_->qvel + proxy_dof_[i];
    s.p_W = proxy_origin_[i] + Vec3(q[0], q[1], q[2]);
    s.v_W = Vec3(v[0], v[1], v[2]);
    s.plane_count = 0;
  }
  for (int c = 0; c < data_->ncon; ++c) {
    const mjContact& con = data_->contact[c];
    for (std::size_t i = 0; i < proxy_geom_.size(); ++i) {
      double sign = 0;
      if (con.geom1 == proxy_geom_[i]) sign = -1;  // frame normal points from geom1 to geom2
      if (con.geom2 == proxy_geom_[i]) sign = +1;
      if (sign == 0) continue;
      ProxyState& s = proxies_[i];
      if (s.plane_count >= kMaxPlanes) continue;
      const Vec3 n = sign * Vec3(con.frame[0], con.frame[1], con.frame[2]);
      // The surface point is the contact position moved half the penetration toward the object.
      const Vec3 surface = Vec3(con.pos[0], con.pos[1], con.pos[2]) - 0.5 * con.dist * n;
      s.planes[s.plane_count++] = {n, n.dot(surface) + r};
    }
  }
}

void World::snapshot(SceneSnapshot& out, bool include_proxies) const {
  out.t_s = data_->time;
  out.meshes = meshes_;
  out.shapes.clear();
  for (int g = 0; g < model_->ngeom; ++g) {
    if (model_->geom_rgba[4 * g + 3] <= 0.0f) continue;
    if (!include_proxies &&
        std::find(proxy_geom_.begin(), proxy_geom_.end(), g) != proxy_geom_.end()) continue;
    Shape s;
    const double* size = model_->geom_size + 3 * g;
    s.size = Vec3(size[0], size[1], size[2]);
    switch (model_->geom_type[g]) {
      case mjGEOM_PLANE: s.type = Shape::Type::kPlane; break;
      case mjGEOM_SPHERE: s.type = Shape::Type::kSphere; break;
      case mjGEOM_CAPSULE: s.type = Shape::Type::kCapsule; break;
      case mjGEOM_CYLINDER: s.type = Shape::Type::kCylinder; break;
      case mjGEOM_BOX: s.type = Shape::Type::kBox; break;
      case mjGEOM_MESH:
        s.type = Shape::Type::kMesh;
        s.mesh = model_->geom_dataid[g];
        break;
      default: continue;  // ellipsoids, height fields: not drawn yet
    }
    const double* x = data_->geom_xpos + 3 * g;
    const double* R = data_->geom_xmat + 9 * g;
    s.X_WS.p = Vec3(x[0], x[1], x[2]);
    Mat3 M;
    M << R[0], R[1], R[2], R[3], R[4], R[5], R[6], R[7], R[8];
    s.X_WS.R = Quat(M);
    for (int k = 0; k < 4; ++k) s.rgba[k] = model_->geom_rgba[4 * g + k];
    s.body = model_->geom_bodyid[g];
    out.shapes.push_back(s);
  }
}

}  // namespace spidar::physics
