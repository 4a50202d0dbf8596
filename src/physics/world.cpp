#include "spidar/physics/world.hpp"

#include <algorithm>

#include <mujoco/mujoco.h>

#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string_view>

#include "spidar/physics/mujoco_log.hpp"

namespace spidar::physics {
namespace {

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

namespace {

int line_at(const std::string& text, std::size_t pos) {
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(pos), '\n'));
}

/// Where the last real closing worldbody tag starts in an MJCF text: a tiny XML scanner that
/// skips comments, CDATA sections, processing instructions and declarations, so a
/// "</worldbody>" inside any of them is not taken for the tag.
Result<std::size_t> find_worldbody_end(const std::string& xml) {
  static constexpr std::string_view kTag = "</worldbody";
  std::size_t found = std::string::npos;
  std::size_t i = 0;
  const auto skip_to = [&](std::size_t from, std::string_view close, const char* what) -> Result<std::size_t> {
    const std::size_t e = xml.find(close, from);
    if (e == std::string::npos) {
      return Error{std::string("unterminated ") + what + " starting at line " + std::to_string(line_at(xml, i)) +
                   " (expected '" + std::string(close) + "')"};
    }
    return e + close.size();
  };
  while ((i = xml.find('<', i)) != std::string::npos) {
    const std::string_view rest = std::string_view(xml).substr(i);
    Result<std::size_t> next = i + 1;
    if (rest.starts_with("<!--")) {
      next = skip_to(i + 4, "-->", "comment");
    } else if (rest.starts_with("<![CDATA[")) {
      next = skip_to(i + 9, "]]>", "CDATA section");
    } else if (rest.starts_with("<?")) {
      next = skip_to(i + 2, "?>", "processing instruction");
    } else if (rest.starts_with("<!")) {
      next = skip_to(i + 2, ">", "declaration");
    } else if (rest.starts_with(kTag)) {
      std::size_t k = i + kTag.size();
      while (k < xml.size() && std::isspace(static_cast<unsigned char>(xml[k]))) ++k;
      if (k < xml.size() && xml[k] == '>') found = i;
      next = i + kTag.size();
    }
    if (!next) return next.error();
    i = *next;
  }
  if (found == std::string::npos) {
    return Error{"no </worldbody> (outside comments) to add the fingertip proxies to; expected an "
                 "MJCF scene with a <worldbody>...</worldbody> element"};
  }
  return found;
}

}  // namespace

Result<std::string> inject_proxies(const std::string& mjcf, const ProxyParams& p) {
  const auto found = find_worldbody_end(mjcf);
  if (!found) return found.error();
  const std::size_t pos = *found;
  std::ostringstream os;
  os.precision(9);
  os << "\n    <!-- spidar-mr fingertip proxies -->\n";
  for (int i = 0; i < p.count; ++i) {
    // Parked below the scene until placed; contype 2 / conaffinity 1: they touch the scene
    // (default contype 1) but not each other.
    // Three slide joints: a fingertip proxy translates but does not roll (a rolling sphere would
    // climb a grasped object instead of lifting it).
    os << "    <body name=\"proxy_" << i << "\" pos=\"" << 0.05 * i << " 0 -5\">\n"
       << "      <joint name=\"proxy_" << i << "_x\" type=\"slide\" axis=\"1 0 0\"/>\n"
       << "      <joint name=\"proxy_" << i << "_y\" type=\"slide\" axis=\"0 1 0\"/>\n"
       << "      <joint name=\"proxy_" << i << "_z\" type=\"slide\" axis=\"0 0 1\"/>\n"
       << "      <geom name=\"proxy_" << i << "_geom\" type=\"sphere\" size=\"" << p.radius
       << "\" mass=\"" << p.mass << "\" contype=\"2\" conaffinity=\"1\" condim=\"4\" friction=\""
       << p.friction << " " << p.torsional_friction << " 0.0001\" rgba=\"0.9 0.3 0.3 0.6\"/>\n"
       << "    </body>\n";
  }
  std::string out = mjcf;
  out.insert(pos, os.str());
  return out;
}

Result<std::unique_ptr<World>> World::Load(const std::string& scene_path, const WorldParams& params) {
  namespace fs = std::filesystem;
  install_mujoco_warning_handler();  // before MuJoCo's compiler can warn
  if (!fs::exists(scene_path)) {
    return Error{scene_path + ": scene file not found (expected an MJCF .xml file)"};
  }
  if (params.proxy.count < 0 || params.proxy.count > 16 || !(params.proxy.radius > 0) ||
      !(params.proxy.mass > 0)) {
    return Error{scene_path + ": bad proxy parameters (count 0..16, radius > 0, mass > 0)"};
  }
  auto text = inject_proxies(read_text(scene_path), params.proxy);
  if (!text) return Error{scene_path + ": " + text.error().message};

  // Load from memory under the scene's own file name, so relative assets still resolve against
  // the scene's directory.
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  const std::string name = fs::path(scene_path).filename().string();
  if (mj_makeEmptyFileVFS(vfs.get(), name.c_str(), static_cast<int>(text->size())) != 0) {
    return Error{scene_path + ": could not stage the scene in MuJoCo's virtual file system"};
  }
  const int idx = mj_findFileVFS(vfs.get(), name.c_str());
  std::memcpy(vfs->filedata[idx], text->data(), text->size());
  char err[1024] = "";
  mjModel* m = mj_loadXML(scene_path.c_str(), vfs.get(), err, sizeof(err));
  mj_deleteVFS(vfs.get());
  if (!m) return Error{scene_path + ": MuJoCo could not load the scene: " + std::string(err)};

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
