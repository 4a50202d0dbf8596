#include "spidar/render/renderer.hpp"

#include <cmath>
#include <limits>
#include <optional>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "gl_api.hpp"
#include "primitive_mesh.hpp"

namespace spidar::render {
namespace {

// One program for every pass: which outputs land where is chosen with glDrawBuffers.
constexpr const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 a_position;      // shape frame (unit primitive or mesh)
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec4 a_model0;        // per instance: X_WS · scale, column by column
layout(location = 3) in vec4 a_model1;
layout(location = 4) in vec4 a_model2;
layout(location = 5) in vec4 a_model3;
layout(location = 6) in vec4 a_rgba;
layout(location = 7) in vec4 a_inv_scale2_id; // 1/scale² per axis; hand id in w
layout(location = 8) in vec4 a_extra;         // x: capsule half length [radii], else 0
uniform mat4 u_view;        // world -> camera frame C (OpenCV axes)
uniform mat4 u_projection;  // C -> clip, w_clip = z_C (render/gl_camera.hpp)
out vec3 v_p_C;
out vec3 v_n_C;
out vec4 v_rgba;
flat out uint v_id;
void main() {
  mat4 model = mat4(a_model0, a_model1, a_model2, a_model3);
  // Capsule template: hemispheres pushed apart along z (primitive_mesh.hpp); a no-op otherwise.
  vec3 p = a_position + vec3(0.0, 0.0, sign(a_position.z) * a_extra.x);
  vec4 p_C = u_view * (model * vec4(p, 1.0));
  // Normals of a scaled primitive: (R S)^-T n = R S^-1 n = (R S)(S^-2 n).
  v_n_C = mat3(u_view) * (mat3(model) * (a_normal * a_inv_scale2_id.xyz));
  v_p_C = p_C.xyz;
  v_rgba = a_rgba;
  v_id = uint(a_inv_scale2_id.w + 0.5);
  gl_Position = u_projection * p_C;
}
)";

constexpr const char* kFragmentShader = R"(#version 330 core
in vec3 v_p_C;
in vec3 v_n_C;
in vec4 v_rgba;
flat in uint v_id;
uniform vec3 u_light_C;   // toward the light, unit
uniform float u_ambient;
layout(location = 0) out vec4 o_colour;
layout(location = 1) out float o_depth;
layout(location = 2) out float o_hand_depth;
layout(location = 3) out uint o_hand_id;
void main() {
  vec3 n = normalize(v_n_C);
  if (dot(n, v_p_C) > 0.0) n = -n;  // two-sided: face the viewer
  float lit = u_ambient + (1.0 - u_ambient) * max(dot(n, u_light_C), 0.0);
  o_colour = vec4(v_rgba.rgb * lit, 1.0);
  o_depth = v_p_C.z;
  o_hand_depth = v_p_C.z;
  o_hand_id = v_id;
}
)";

// Shown by present(): a full-screen blit needs no shader.

struct Instance {
  float model[16];
  float rgba[4];
  float inv_scale2_id[4];
  float extra[4];
};
static_assert(sizeof(Instance) == 28 * sizeof(float));

struct GpuMesh {
  GLuint vao = 0, vbo = 0, ebo = 0;
  GLsizei index_count = 0;
  std::size_t vertex_bytes = 0, index_bytes = 0;  // sizes of the buffers' stores
  std::uint64_t version = 0;                      // MeshData::version uploaded
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();  // vertex bounds
};

/// The bounding box of a mesh's vertex positions (zero for no vertices).
void set_bounds(const CpuMesh& cpu, GpuMesh* m) {
  m->lo.setZero();
  m->hi.setZero();
  for (std::size_t i = 0; i + 6 <= cpu.vertices.size(); i += 6) {
    const Eigen::Vector3d p(cpu.vertices[i], cpu.vertices[i + 1], cpu.vertices[i + 2]);
    m->lo = i == 0 ? p : m->lo.cwiseMin(p);
    m->hi = i == 0 ? p : m->hi.cwiseMax(p);
  }
}

enum Primitive : int {
  kBoxMesh = 0,
  kSphereMesh,
  kCylinderMesh,
  kQuadMesh,
  kCapsuleMesh,
  kPrimitiveCount
};

Status compile(GLenum type, const char* source, GLuint* out) {
  const GLuint s = gl::CreateShader(type);
  gl::ShaderSource(s, 1, &source, nullptr);
  gl::CompileShader(s);
  GLint ok = 0;
  gl::GetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    gl::GetShaderInfoLog(s, sizeof log, nullptr, log);
    gl::DeleteShader(s);
    return Error{std::string("renderer: ") +
                 (type == GL_VERTEX_SHADER ? "vertex" : "fragment") +
                 " shader does not compile: " + log};
  }
  *out = s;
  return Ok{};
}

/// Clears the bound framebuffer's colour target (draw buffer 0) to the background and its depth
/// target (draw buffer 1) to +inf (nothing there).
void clear_colour_and_depth_targets(const RenderParams& params) {
  const float inf = std::numeric_limits<float>::infinity();
  const float bg[4] = {params.background_rgb[0], params.background_rgb[1], params.background_rgb[2], 1.f};
  const float far_value[4] = {inf, inf, inf, inf};
  gl::ClearBufferfv(GL_COLOR, 0, bg);
  gl::ClearBufferfv(GL_COLOR, 1, far_value);
}

}  // namespace

struct Renderer::Impl {
  Context* context = nullptr;
  int width = 0, height = 0;
  GLuint program = 0;
  GLint u_view = -1, u_projection = -1, u_light = -1, u_ambient = -1;
  /// A framebuffer with some of the four target formats (colour RGBA8, depth R32F, hand depth
  /// R32F, hand id R8UI), format k as colour attachment k, and a 32-bit float depth buffer.
  struct Framebuffer {
    GLuint fbo = 0, depth_rb = 0;
    GLuint tex[4] = {};
  };
  Framebuffer frame;  ///< all four targets: what render() draws and read() reads
  /// The frame's depth buffer for the hand pass (frame.depth_rb serves the scene pass): the
  /// scene's is overwritten by the static world each frame, this one only by hands, so only the
  /// pixels the last hands covered need resetting.
  GLuint hand_depth_rb = 0;
  /// The pixels the last hand pass wrote (rows as in the image, which are GL's rows): the bounding
  /// box of hand_id != 0, known when read() read the hand id after the last render().
  mutable cv::Rect hands_written;
  mutable bool hands_written_known = false;
  /// The pixels the last frame's moving objects may have covered in colour, depth and the scene's
  /// depth buffer (a bound from their bounding boxes), known when that frame started from the
  /// static world's copy and drew nothing else there.
  cv::Rect scene_written;
  bool scene_written_known = false;
  GLuint instance_vbo = 0;
  std::size_t instance_capacity = 0;
  GpuMesh primitives[kPrimitiveCount];
  // Snapshot meshes, per mesh list (a few lists alive at once, e.g. scene and synthetic hands).
  struct MeshSet {
    std::weak_ptr<const std::vector<MeshData>> source;
    const void* key = nullptr;
    std::vector<GpuMesh> meshes;
  };
  std::vector<MeshSet> mesh_sets;
  CpuMesh staging;  // a changed mesh on its way to the GPU (reused: no allocation per frame)
  // Per frame, reused: instances per draw key (primitive, then meshes), objects and hands.
  std::vector<std::vector<Instance>> object_batches, hand_batches, static_batches;
  std::vector<Instance> upload;
  // The static world (RenderParams::cache_static): its colour, depth target and depth buffer,
  // drawn once and copied in each frame while `static_key` (its instances and the view) holds.
  Framebuffer static_world;
  bool static_valid = false;
  // Hand depth (+inf), hand id (0) and the depth buffer (1) at their cleared values, cleared once
  // and copied into the frame's targets at the start of each render: llvmpipe copies a target
  // faster than it clears one (it fills a cleared tile pixel by pixel).
  Framebuffer blank;
  std::vector<float> static_key, key_scratch;
  GLuint present_fbo = 0, present_tex = 0;
  mutable cv::Mat colour_rgba;  ///< read(): the colour target as read back (reused)
  int present_w = 0, present_h = 0;

  ~Impl() {
    if (context == nullptr) return;
    (void)context->make_current();
    for (auto& m : primitives) destroy(m);
    for (auto& set : mesh_sets)
      for (auto& m : set.meshes) destroy(m);
    if (instance_vbo) gl::DeleteBuffers(1, &instance_vbo);
    destroy_targets();
    if (present_fbo) gl::DeleteFramebuffers(1, &present_fbo);
    if (present_tex) gl::DeleteTextures(1, &present_tex);
    if (program) gl::DeleteProgram(program);
  }

  static void destroy(GpuMesh& m) {
    if (m.vao) gl::DeleteVertexArrays(1, &m.vao);
    if (m.vbo) gl::DeleteBuffers(1, &m.vbo);
    if (m.ebo) gl::DeleteBuffers(1, &m.ebo);
    m = {};
  }

  static void destroy(Framebuffer& f) {
    if (f.fbo) gl::DeleteFramebuffers(1, &f.fbo);
    if (f.depth_rb) gl::DeleteRenderbuffers(1, &f.depth_rb);
    for (GLuint& t : f.tex)
      if (t) gl::DeleteTextures(1, &t);
    f = {};
  }

  void destroy_targets() {
    destroy(frame);
    if (hand_depth_rb) gl::DeleteRenderbuffers(1, &hand_depth_rb);
    hand_depth_rb = 0;
    hands_written_known = false;
    scene_written_known = false;
    destroy(static_world);
    destroy(blank);
    static_valid = false;
  }

  /// Makes `f` at the current size with the target formats in `targets` (a Target mask: bit k,
  /// format k) and a depth buffer. Leaves it bound.
  Status make_targets(unsigned targets, Framebuffer* f, const char* what) {
    const GLint internal[4] = {GL_RGBA8, GL_R32F, GL_R32F, GL_R8UI};
    const GLenum format[4] = {GL_RGBA, GL_RED, GL_RED, GL_RED_INTEGER};
    const GLenum type[4] = {GL_UNSIGNED_BYTE, GL_FLOAT, GL_FLOAT, GL_UNSIGNED_BYTE};
    gl::GenFramebuffers(1, &f->fbo);
    gl::BindFramebuffer(GL_FRAMEBUFFER, f->fbo);
    for (int i = 0; i < 4; ++i) {
      if (!(targets & (1u << i))) continue;
      gl::GenTextures(1, &f->tex[i]);
      gl::BindTexture(GL_TEXTURE_2D, f->tex[i]);
      gl::TexImage2D(GL_TEXTURE_2D, 0, internal[i], width, height, 0, format[i], type[i], nullptr);
      gl::TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
      gl::TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
      gl::FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(i),
                               GL_TEXTURE_2D, f->tex[i], 0);
    }
    f->depth_rb = make_depth_buffer();
    gl::FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, f->depth_rb);
    const GLenum status = gl::CheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE)
      return Error{std::string("renderer: ") + what + " " + std::to_string(width) + "x" +
                   std::to_string(height) + " incomplete (status 0x" + std::to_string(status) + ")"};
    return gl::check_gl((std::string("renderer: creating ") + what).c_str());
  }

  /// A 32-bit float depth buffer of the current size.
  GLuint make_depth_buffer() const {
    GLuint rb = 0;
    gl::GenRenderbuffers(1, &rb);
    gl::BindRenderbuffer(GL_RENDERBUFFER, rb);
    gl::RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, width, height);
    return rb;
  }

  /// Attaches `rb` as the frame's depth buffer (the frame stays bound).
  void use_frame_depth_buffer(GLuint rb) const {
    gl::BindFramebuffer(GL_FRAMEBUFFER, frame.fbo);
    gl::FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, rb);
  }

  /// The whole image, in pixels.
  cv::Rect whole() const { return {0, 0, width, height}; }

  /// Copies the colour attachments in `targets` (a Target mask) and the depth buffer of `from`
  /// into the same attachments of `to` within `region` (pixels, image rows = GL rows; nothing if
  /// empty): same sizes and formats, nearest, so a plain copy (Mesa copies the resource's region).
  /// Leaves `to` bound for drawing, with its draw buffers changed.
  void copy_targets(const Framebuffer& from, const Framebuffer& to, unsigned targets,
                    const cv::Rect& region) const {
    gl::BindFramebuffer(GL_DRAW_FRAMEBUFFER, to.fbo);
    if (region.area() <= 0) return;
    const GLint x0 = region.x, y0 = region.y, x1 = region.x + region.width,
                y1 = region.y + region.height;
    gl::BindFramebuffer(GL_READ_FRAMEBUFFER, from.fbo);
    gl::BindFramebuffer(GL_DRAW_FRAMEBUFFER, to.fbo);
    for (GLenum i = 0; i < 4; ++i) {
      if (!(targets & (1u << i))) continue;
      gl::ReadBuffer(GL_COLOR_ATTACHMENT0 + i);
      GLenum only[4] = {GL_NONE, GL_NONE, GL_NONE, GL_NONE};
      only[i] = GL_COLOR_ATTACHMENT0 + i;
      gl::DrawBuffers(4, only);
      gl::BlitFramebuffer(x0, y0, x1, y1, x0, y0, x1, y1, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    }
    gl::BlitFramebuffer(x0, y0, x1, y1, x0, y0, x1, y1, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
    gl::BindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  }

  /// Resets the frame's hand depth, hand id and hand depth buffer to +inf, 0 and 1 by copying
  /// `blank` (made and cleared on first use): only where the last hand pass wrote when that is
  /// known, everywhere else. Leaves the frame bound with the hand depth buffer attached, its draw
  /// buffers changed.
  Status reset_hand_targets() {
    if (!blank.fbo) {
      if (auto st = make_targets(kHandDepth | kHandId, &blank, "blank hand targets"); !st) return st;
      const GLenum hand[4] = {GL_NONE, GL_NONE, GL_COLOR_ATTACHMENT2, GL_COLOR_ATTACHMENT3};
      gl::DrawBuffers(4, hand);
      const float inf = std::numeric_limits<float>::infinity();
      const float far_value[4] = {inf, inf, inf, inf};
      const GLuint no_hand[4] = {0, 0, 0, 0};
      gl::ClearBufferfv(GL_COLOR, 2, far_value);
      gl::ClearBufferuiv(GL_COLOR, 3, no_hand);
      gl::ClearBufferfi(GL_DEPTH_STENCIL, 0, 1.f, 0);
    }
    use_frame_depth_buffer(hand_depth_rb);
    copy_targets(blank, frame, kHandDepth | kHandId, hands_written_known ? hands_written : whole());
    hands_written_known = false;  // until read() sees this frame's hand id
    gl::BindFramebuffer(GL_FRAMEBUFFER, frame.fbo);
    return gl::check_gl("renderer: resetting the hand targets");
  }

  Status create_program() {
    GLuint vs = 0, fs = 0;
    if (auto s = compile(GL_VERTEX_SHADER, kVertexShader, &vs); !s) return s;
    if (auto s = compile(GL_FRAGMENT_SHADER, kFragmentShader, &fs); !s) {
      gl::DeleteShader(vs);
      return s;
    }
    program = gl::CreateProgram();
    gl::AttachShader(program, vs);
    gl::AttachShader(program, fs);
    gl::LinkProgram(program);
    gl::DeleteShader(vs);
    gl::DeleteShader(fs);
    GLint ok = 0;
    gl::GetProgramiv(program, GL_LINK_STATUS, &ok);
    if (!ok) {
      char log[2048] = {};
      gl::GetProgramInfoLog(program, sizeof log, nullptr, log);
      return Error{std::string("renderer: shader program does not link: ") + log};
    }
    u_view = gl::GetUniformLocation(program, "u_view");
    u_projection = gl::GetUniformLocation(program, "u_projection");
    u_light = gl::GetUniformLocation(program, "u_light_C");
    u_ambient = gl::GetUniformLocation(program, "u_ambient");
    return gl::check_gl("renderer: shader set-up");
  }

  Status create_targets(int w, int h) {
    destroy_targets();
    width = w;
    height = h;
    if (auto st = make_targets(kAllTargets, &frame, "offscreen targets"); !st) return st;
    hand_depth_rb = make_depth_buffer();
    return gl::check_gl("renderer: creating the hand depth buffer");
  }

  GpuMesh upload_mesh(const CpuMesh& cpu) {
    GpuMesh m;
    gl::GenVertexArrays(1, &m.vao);
    gl::BindVertexArray(m.vao);
    gl::GenBuffers(1, &m.vbo);
    gl::BindBuffer(GL_ARRAY_BUFFER, m.vbo);
    gl::BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(cpu.vertices.size() * sizeof(float)),
                   cpu.vertices.data(), GL_STATIC_DRAW);
    gl::EnableVertexAttribArray(0);
    gl::VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
    gl::EnableVertexAttribArray(1);
    gl::VertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float),
                            reinterpret_cast<const void*>(3 * sizeof(float)));
    gl::GenBuffers(1, &m.ebo);
    gl::BindBuffer(GL_ELEMENT_ARRAY_BUFFER, m.ebo);
    gl::BufferData(GL_ELEMENT_ARRAY_BUFFER,
                   static_cast<GLsizeiptr>(cpu.indices.size() * sizeof(std::uint32_t)),
                   cpu.indices.data(), GL_STATIC_DRAW);
    m.index_count = static_cast<GLsizei>(cpu.indices.size());
    set_bounds(cpu, &m);
    m.vertex_bytes = cpu.vertices.size() * sizeof(float);
    m.index_bytes = cpu.indices.size() * sizeof(std::uint32_t);
    // Per-instance attributes 2..7 come from the shared instance buffer; their offsets are set
    // before each draw (GL 3.3 has no base instance).
    gl::BindBuffer(GL_ARRAY_BUFFER, instance_vbo);
    for (GLuint a = 2; a <= 8; ++a) {
      gl::EnableVertexAttribArray(a);
      gl::VertexAttribDivisor(a, 1);
    }
    gl::BindVertexArray(0);
    return m;
  }

  /// Uploads a changed mesh's contents into its buffers: in place (glBufferSubData) when the
  /// sizes are unchanged, else into new stores.
  void reupload_mesh(const MeshData& md, GpuMesh& m) {
    snapshot_mesh(md, &staging);
    const std::size_t vbytes = staging.vertices.size() * sizeof(float);
    const std::size_t ibytes = staging.indices.size() * sizeof(std::uint32_t);
    gl::BindVertexArray(m.vao);  // the element buffer binding belongs to the VAO
    gl::BindBuffer(GL_ARRAY_BUFFER, m.vbo);
    if (vbytes == m.vertex_bytes) {
      gl::BufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(vbytes), staging.vertices.data());
    } else {
      gl::BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vbytes), staging.vertices.data(),
                     GL_DYNAMIC_DRAW);
      m.vertex_bytes = vbytes;
    }
    gl::BindBuffer(GL_ELEMENT_ARRAY_BUFFER, m.ebo);
    if (ibytes == m.index_bytes) {
      gl::BufferSubData(GL_ELEMENT_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(ibytes), staging.indices.data());
    } else {
      gl::BufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(ibytes), staging.indices.data(),
                     GL_DYNAMIC_DRAW);
      m.index_bytes = ibytes;
    }
    m.index_count = static_cast<GLsizei>(staging.indices.size());
    set_bounds(staging, &m);
    m.version = md.version;
    gl::BindVertexArray(0);
  }

  /// The uploaded meshes of a snapshot's mesh list (uploading them the first time, and again
  /// each mesh whose MeshData::version changed since).
  const std::vector<GpuMesh>* meshes_for(const SceneSnapshot& scene) {
    if (!scene.meshes || scene.meshes->empty()) return nullptr;
    const void* key = scene.meshes.get();
    for (auto& set : mesh_sets) {
      if (set.key != key || set.source.expired()) continue;
      const std::vector<MeshData>& source = *scene.meshes;
      for (std::size_t i = 0; i < source.size() && i < set.meshes.size(); ++i)
        if (source[i].version != set.meshes[i].version) reupload_mesh(source[i], set.meshes[i]);
      for (std::size_t i = set.meshes.size(); i < source.size(); ++i) {  // the list grew
        snapshot_mesh(source[i], &staging);
        set.meshes.push_back(upload_mesh(staging));
        set.meshes.back().version = source[i].version;
      }
      return &set.meshes;
    }
    // Drop sets whose lists are gone, and the oldest beyond four.
    for (std::size_t i = 0; i < mesh_sets.size();) {
      if (mesh_sets[i].source.expired() || mesh_sets.size() >= 4) {
        for (auto& m : mesh_sets[i].meshes) destroy(m);
        mesh_sets.erase(mesh_sets.begin() + static_cast<std::ptrdiff_t>(i));
      } else {
        ++i;
      }
    }
    MeshSet set;
    set.source = scene.meshes;
    set.key = key;
    for (const MeshData& md : *scene.meshes) {
      snapshot_mesh(md, &staging);
      set.meshes.push_back(upload_mesh(staging));
      set.meshes.back().version = md.version;
    }
    mesh_sets.push_back(std::move(set));
    return &mesh_sets.back().meshes;
  }

  static Instance make_instance(const Pose& X_WS, const Vec3& scale, const std::array<float, 4>& rgba,
                                std::uint8_t id, float capsule_half_length = 0.f) {
    Instance inst{};
    inst.extra[0] = capsule_half_length;
    Mat4 M = X_WS.matrix();
    M.block<3, 3>(0, 0) = M.block<3, 3>(0, 0) * scale.asDiagonal();
    const Eigen::Matrix4f Mf = M.cast<float>();
    std::copy(Mf.data(), Mf.data() + 16, inst.model);  // column-major, as GL wants
    std::copy(rgba.begin(), rgba.end(), inst.rgba);
    for (int k = 0; k < 3; ++k) inst.inv_scale2_id[k] = static_cast<float>(1.0 / (scale[k] * scale[k]));
    inst.inv_scale2_id[3] = static_cast<float>(id);
    return inst;
  }

  /// Sorts the snapshot's shapes into per-mesh instance batches.
  /// Static shapes (`split_static`): the world body's (body 0) primitives; its meshes stay with
  /// the objects, since a mesh's contents can change under the same instance.
  void batch(const SceneSnapshot& scene, const std::vector<GpuMesh>* meshes, bool split_static) {
    const std::size_t keys = kPrimitiveCount + (meshes ? meshes->size() : 0);
    for (auto* batches : {&object_batches, &hand_batches, &static_batches}) {
      batches->resize(keys);
      for (auto& b : *batches) b.clear();
    }
    for (const Shape& s : scene.shapes) {
      if (!s.X_WS.p.allFinite() || !s.X_WS.R.coeffs().allFinite() || !s.size.allFinite()) continue;
      const bool hand = s.hand >= 0;
      const bool fixed = split_static && !hand && s.body == 0 && s.type != Shape::Type::kMesh;
      auto& batches = hand ? hand_batches : (fixed ? static_batches : object_batches);
      const std::uint8_t id = hand ? encode_hand_id(s.hand, s.finger) : 0;
      const double tiny = 1e-9;  // degenerate sizes stay invertible for the normals
      auto add = [&](int key, const Pose& X, const Vec3& scale, float capsule = 0.f) {
        batches[static_cast<std::size_t>(key)].push_back(
            make_instance(X, scale.cwiseMax(tiny), s.rgba, id, capsule));
      };
      const Vec3& z = s.size;
      switch (s.type) {
        case Shape::Type::kBox: add(kBoxMesh, s.X_WS, z); break;
        case Shape::Type::kSphere: add(kSphereMesh, s.X_WS, Vec3::Constant(z.x())); break;
        case Shape::Type::kCylinder: add(kCylinderMesh, s.X_WS, Vec3(z.x(), z.x(), z.y())); break;
        case Shape::Type::kCapsule: {
          const double r = std::max(z.x(), tiny);
          add(kCapsuleMesh, s.X_WS, Vec3::Constant(r), static_cast<float>(std::max(z.y(), 0.0) / r));
          break;
        }
        case Shape::Type::kPlane:
          add(kQuadMesh, s.X_WS, Vec3(z.x() > 0 ? z.x() : 5.0, z.y() > 0 ? z.y() : 5.0, 1.0));
          break;
        case Shape::Type::kMesh:
          if (meshes && s.mesh >= 0 && static_cast<std::size_t>(s.mesh) < meshes->size())
            add(kPrimitiveCount + s.mesh, s.X_WS, Vec3::Ones());
          break;
      }
    }
  }

  /// Pass 2's start when there are static shapes: brings the static world's cache up to date
  /// (drawn again only when its instances or the view changed) and copies its colour, depth
  /// target and depth buffer into the frame's targets: where the last frame's objects may have
  /// drawn (`written`) when the cache holds and that is known, else everywhere. Static instances
  /// sit in the instance buffer from `first` on. Leaves the main targets bound for drawing.
  Status draw_static(const Eigen::Matrix4f& view, const Eigen::Matrix4f& projection,
                     const Eigen::Vector3f& light, const RenderParams& params,
                     const std::vector<GpuMesh>* meshes, std::size_t first,
                     std::optional<cv::Rect> written) {
    key_scratch.clear();
    for (std::size_t k = 0; k < static_batches.size(); ++k) {
      if (static_batches[k].empty()) continue;
      key_scratch.push_back(static_cast<float>(k));
      for (const Instance& inst : static_batches[k]) {
        const auto* f = reinterpret_cast<const float*>(&inst);
        key_scratch.insert(key_scratch.end(), f, f + sizeof(Instance) / sizeof(float));
      }
    }
    key_scratch.insert(key_scratch.end(), view.data(), view.data() + 16);
    key_scratch.insert(key_scratch.end(), projection.data(), projection.data() + 16);
    key_scratch.insert(key_scratch.end(), {light.x(), light.y(), light.z(), params.ambient,
                                           params.background_rgb[0], params.background_rgb[1],
                                           params.background_rgb[2]});
    if (!static_world.fbo) {
      if (auto st = make_targets(kColour | kDepth, &static_world, "static-world targets"); !st) return st;
    }
    if (!static_valid || key_scratch != static_key) {
      gl::BindFramebuffer(GL_FRAMEBUFFER, static_world.fbo);
      const GLenum targets[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
      gl::DrawBuffers(2, targets);
      clear_colour_and_depth_targets(params);
      gl::ClearBufferfi(GL_DEPTH_STENCIL, 0, 1.f, 0);
      draw(static_batches, first, meshes);
      static_key.swap(key_scratch);
      static_valid = true;
      written.reset();
    }
    copy_targets(static_world, frame, kColour | kDepth, written ? *written : whole());
    return gl::check_gl("renderer: static world");
  }

  const GpuMesh& mesh_of(std::size_t key, const std::vector<GpuMesh>* meshes) const {
    return key < kPrimitiveCount ? primitives[key] : (*meshes)[key - kPrimitiveCount];
  }

  /// Pixels (image rows) that hold every fragment the instances of `batches` can draw seen by
  /// `camera`: the projections of the corners of their bounding boxes (the capsule template's
  /// stretched by its half length), grown by a pixel each side. Fragments lie inside the convex
  /// hull of those projections when every corner is in front of the camera; when one is not,
  /// the whole image.
  cv::Rect screen_bounds(const std::vector<std::vector<Instance>>& batches,
                         const std::vector<GpuMesh>* meshes, const vision::Camera& camera) const {
    const vision::Intrinsics& K = camera.intrinsics();
    const Mat4 X_CW = camera.X_CW().matrix();
    double u0 = 1e300, v0 = 1e300, u1 = -1e300, v1 = -1e300;
    for (std::size_t key = 0; key < batches.size(); ++key) {
      if (batches[key].empty()) continue;
      const GpuMesh& m = mesh_of(key, meshes);
      for (const Instance& inst : batches[key]) {
        const Mat4 X_CS = X_CW * Eigen::Map<const Eigen::Matrix4f>(inst.model).cast<double>();
        const double stretch = key == kCapsuleMesh ? inst.extra[0] : 0.0;
        for (int c = 0; c < 8; ++c) {
          Vec3 p_S((c & 1) ? m.hi.x() : m.lo.x(), (c & 2) ? m.hi.y() : m.lo.y(),
                   (c & 4) ? m.hi.z() + stretch : m.lo.z() - stretch);
          const Vec3 p_C = (X_CS * p_S.homogeneous()).head<3>();
          if (!(p_C.z() > 1e-6)) return whole();
          const double u = K.fx * p_C.x() / p_C.z() + K.cx, v = K.fy * p_C.y() / p_C.z() + K.cy;
          u0 = std::min(u0, u), u1 = std::max(u1, u), v0 = std::min(v0, v), v1 = std::max(v1, v);
        }
      }
    }
    if (u0 > u1) return {};  // nothing drawn
    // Pixel i holds the image points u in [i - 1/2, i + 1/2]; one more pixel each side.
    auto first = [](double a) { return static_cast<int>(std::floor(std::max(a, -1e9))) - 1; };
    auto last = [](double a) { return static_cast<int>(std::ceil(std::min(a, 1e9))) + 1; };
    return cv::Rect(cv::Point(first(u0), first(v0)), cv::Point(last(u1) + 1, last(v1) + 1)) & whole();
  }

  /// Draws batches whose instances sit in the instance buffer from `first` on.
  void draw(const std::vector<std::vector<Instance>>& batches, std::size_t first,
            const std::vector<GpuMesh>* meshes) {
    std::size_t offset = first;
    for (std::size_t key = 0; key < batches.size(); ++key) {
      const auto count = batches[key].size();
      if (count == 0) continue;
      const GpuMesh& m = mesh_of(key, meshes);
      gl::BindVertexArray(m.vao);
      gl::BindBuffer(GL_ARRAY_BUFFER, instance_vbo);
      const std::size_t base = offset * sizeof(Instance);
      for (GLuint a = 0; a < 7; ++a) {
        const std::size_t at = base + 4 * a * sizeof(float);  // seven vec4s, in order
        gl::VertexAttribPointer(2 + a, 4, GL_FLOAT, GL_FALSE, sizeof(Instance),
                                reinterpret_cast<const void*>(at));
      }
      gl::DrawElementsInstanced(GL_TRIANGLES, m.index_count, GL_UNSIGNED_INT, nullptr,
                                static_cast<GLsizei>(count));
      offset += count;
    }
  }
};

Renderer::Renderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Renderer::~Renderer() = default;

int Renderer::width() const { return impl_->width; }
int Renderer::height() const { return impl_->height; }

Result<std::unique_ptr<Renderer>> Renderer::create(Context& context, int width, int height) {
  if (width <= 0 || height <= 0 || width > 16384 || height > 16384)
    return Error{"renderer: image size must be within 1..16384 px, got " + std::to_string(width) +
                 "x" + std::to_string(height)};
  if (auto s = context.make_current(); !s) return s.error();
  auto impl = std::make_unique<Impl>();
  impl->context = &context;
  if (auto s = impl->create_program(); !s) return s.error();
  gl::GenBuffers(1, &impl->instance_vbo);
  const CpuMesh cpu[kPrimitiveCount] = {unit_box(), unit_sphere(20, 12), unit_cylinder(20),
                                        unit_quad(), unit_capsule_template()};
  for (int i = 0; i < kPrimitiveCount; ++i) impl->primitives[i] = impl->upload_mesh(cpu[i]);
  if (auto s = impl->create_targets(width, height); !s) return s.error();
  return std::unique_ptr<Renderer>(new Renderer(std::move(impl)));
}

Status Renderer::render(const SceneSnapshot& scene, const vision::Camera& camera,
                        const RenderParams& params) {
  Impl& r = *impl_;
  if (auto s = validate(params.depth_range); !s) return s;
  if (camera.width() <= 0 || camera.height() <= 0)
    return Error{"renderer: camera image size must be positive"};
  if (camera.width() != r.width || camera.height() != r.height) {
    if (auto s = r.create_targets(camera.width(), camera.height()); !s) return s;
  }
  const std::vector<GpuMesh>* meshes = r.meshes_for(scene);
  r.batch(scene, meshes, params.cache_static);
  if (params.hands == HandDrawMode::kVisible && !params.hands_keep_colour)
    for (auto& b : r.hand_batches)
      for (auto& inst : b) std::copy(params.visible_hand_rgba.begin(), params.visible_hand_rgba.end(), inst.rgba);

  // One upload: object instances, then hand instances, then static ones.
  r.upload.clear();
  for (auto* batches : {&r.object_batches, &r.hand_batches, &r.static_batches})
    for (auto& b : *batches) r.upload.insert(r.upload.end(), b.begin(), b.end());
  std::size_t object_count = 0, hand_count = 0, static_count = 0;
  for (auto& b : r.object_batches) object_count += b.size();
  for (auto& b : r.hand_batches) hand_count += b.size();
  for (auto& b : r.static_batches) static_count += b.size();
  gl::BindBuffer(GL_ARRAY_BUFFER, r.instance_vbo);
  const std::size_t bytes = std::max<std::size_t>(r.upload.size(), 1) * sizeof(Instance);
  if (bytes > r.instance_capacity) {
    r.instance_capacity = bytes * 2;
    gl::BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(r.instance_capacity), nullptr,
                   GL_STREAM_DRAW);
  }
  if (!r.upload.empty())
    gl::BufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(r.upload.size() * sizeof(Instance)),
                      r.upload.data());

  gl::BindFramebuffer(GL_FRAMEBUFFER, r.frame.fbo);
  gl::Viewport(0, 0, r.width, r.height);
  gl::Enable(GL_DEPTH_TEST);
  gl::DepthFunc(GL_LESS);
  gl::DepthMask(GL_TRUE);
  gl::Enable(GL_CULL_FACE);
  gl::CullFace(GL_BACK);
  gl::FrontFace(GL_CW);  // image rows top-first mirror the winding (gl_camera.hpp)
  gl::UseProgram(r.program);
  const Eigen::Matrix4f view = gl_view(camera.X_CW()).cast<float>();
  const Eigen::Matrix4f projection =
      gl_projection(camera.intrinsics(), params.depth_range).cast<float>();
  gl::UniformMatrix4fv(r.u_view, 1, GL_FALSE, view.data());
  gl::UniformMatrix4fv(r.u_projection, 1, GL_FALSE, projection.data());
  const Eigen::Vector3f light = params.light_dir_C.normalized().cast<float>();
  gl::Uniform3f(r.u_light, light.x(), light.y(), light.z());
  gl::Uniform1f(r.u_ambient, params.ambient);

  // Colour and the depth target are cleared only when no static world is copied over them
  // (software GL pays for a clear per pixel); the hand targets and the depth buffer are copied
  // from their blank copies.
  if (static_count == 0) {
    const GLenum scene_targets[4] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_NONE, GL_NONE};
    gl::DrawBuffers(4, scene_targets);
    clear_colour_and_depth_targets(params);
  }
  if (auto st = r.reset_hand_targets(); !st) return st;

  // Pass 1: hands into hand depth and hand id. With visible hands and no scene objects, colour
  // too: nothing could occlude them, so the separate colour pass below is not needed.
  const bool hands_only = object_count + static_count == 0 && params.hands == HandDrawMode::kVisible;
  const GLenum hand_targets[4] = {hands_only ? GLenum{GL_COLOR_ATTACHMENT0} : GLenum{GL_NONE}, GL_NONE,
                                  GL_COLOR_ATTACHMENT2, GL_COLOR_ATTACHMENT3};
  gl::DrawBuffers(4, hand_targets);
  r.draw(r.hand_batches, object_count, meshes);
  if (hands_only) {
    gl::BindVertexArray(0);
    return gl::check_gl("renderer: render");
  }
  // Pass 2: the scene into colour and depth, with its own depth buffer, fresh: the static
  // world's (colour, depth target and depth buffer copied from its cache), then the moving
  // objects.
  const GLenum scene_targets[4] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_NONE, GL_NONE};
  r.use_frame_depth_buffer(r.frame.depth_rb);
  const std::optional<cv::Rect> written =
      r.scene_written_known ? std::optional<cv::Rect>(r.scene_written) : std::nullopt;
  r.scene_written_known = false;
  if (static_count > 0) {
    if (auto st = r.draw_static(view, projection, light, params, meshes, object_count + hand_count, written); !st)
      return st;
    gl::BindFramebuffer(GL_FRAMEBUFFER, r.frame.fbo);
  } else {
    gl::ClearBufferfi(GL_DEPTH_STENCIL, 0, 1.f, 0);
  }
  gl::DrawBuffers(4, scene_targets);
  r.draw(r.object_batches, 0, meshes);
  // Where the next frame must restore the static world (when only objects drew over it).
  if (static_count > 0 && params.hands != HandDrawMode::kVisible) {
    r.scene_written = r.screen_bounds(r.object_batches, meshes, camera);
    r.scene_written_known = true;
  }
  // Debugging: visible hands occlude the scene's colour (not its depth target).
  if (params.hands == HandDrawMode::kVisible) {
    const GLenum colour_only[4] = {GL_COLOR_ATTACHMENT0, GL_NONE, GL_NONE, GL_NONE};
    gl::DrawBuffers(4, colour_only);
    r.draw(r.hand_batches, object_count, meshes);
  }
  gl::BindVertexArray(0);
  return gl::check_gl("renderer: render");
}

Status Renderer::read(RenderTargets* out, unsigned targets) const {
  const Impl& r = *impl_;
  if (out == nullptr) return Error{"renderer: read needs an output"};
  gl::BindFramebuffer(GL_READ_FRAMEBUFFER, r.frame.fbo);
  gl::PixelStorei(GL_PACK_ALIGNMENT, 1);
  auto read_one = [&](int attachment, cv::Mat* m, int cv_type, GLenum format, GLenum type) {
    m->create(r.height, r.width, cv_type);
    gl::ReadBuffer(GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(attachment));
    gl::ReadPixels(0, 0, r.width, r.height, format, type, m->data);
  };
  if (targets & kColour) {
    // The colour target's own layout, RGBA8, is read as is (a plain copy in Mesa), then its
    // alpha dropped and red and blue swapped (SIMD): about a fifth of the cost of asking GL for
    // BGR, which Mesa converts pixel by pixel.
    read_one(0, &r.colour_rgba, CV_8UC4, GL_RGBA, GL_UNSIGNED_BYTE);
    cv::cvtColor(r.colour_rgba, out->colour, cv::COLOR_RGBA2BGR);
  }
  if (targets & kDepth) read_one(1, &out->depth, CV_32FC1, GL_RED, GL_FLOAT);
  if (targets & kHandDepth) read_one(2, &out->hand_depth, CV_32FC1, GL_RED, GL_FLOAT);
  if (targets & kHandId) {
    read_one(3, &out->hand_id, CV_8UC1, GL_RED_INTEGER, GL_UNSIGNED_BYTE);
    // Every hand fragment drawn wrote an id ≥ 1: where the next render must reset.
    r.hands_written = cv::boundingRect(out->hand_id);
    r.hands_written_known = true;
    out->hand_box = r.hands_written;
  } else {
    out->hand_box.reset();
  }
  gl::BindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  return gl::check_gl("renderer: read-back");
}

Status Renderer::present(Context& context, const cv::Mat& bgr) {
  Impl& r = *impl_;
  if (context.kind() != ContextKind::kWindow)
    return Error{"renderer: present needs a window context, this one is headless"};
  if (bgr.empty() || bgr.type() != CV_8UC3)
    return Error{"renderer: present expects a non-empty 8-bit BGR image"};
  if (auto s = context.make_current(); !s) return s;
  const cv::Mat img = bgr.isContinuous() ? bgr : bgr.clone();
  if (!r.present_fbo) {
    gl::GenFramebuffers(1, &r.present_fbo);
    gl::GenTextures(1, &r.present_tex);
  }
  gl::BindTexture(GL_TEXTURE_2D, r.present_tex);
  gl::PixelStorei(GL_UNPACK_ALIGNMENT, 1);
  if (img.cols != r.present_w || img.rows != r.present_h) {
    gl::TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, img.cols, img.rows, 0, GL_BGR, GL_UNSIGNED_BYTE,
                   img.data);
    r.present_w = img.cols;
    r.present_h = img.rows;
    gl::BindFramebuffer(GL_READ_FRAMEBUFFER, r.present_fbo);
    gl::FramebufferTexture2D(GL_READ_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D,
                             r.present_tex, 0);
  } else {
    gl::TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, img.cols, img.rows, GL_BGR, GL_UNSIGNED_BYTE,
                      img.data);
  }
  const int W = context.framebuffer_width(), H = context.framebuffer_height();
  // Fit with the aspect ratio kept; the image's row 0 (its top) goes to the window's top, so the
  // destination rectangle runs from y1 (top) down to y0: the one vertical flip of gl_camera.hpp.
  const double scale = std::min(W / static_cast<double>(img.cols), H / static_cast<double>(img.rows));
  const int w = static_cast<int>(img.cols * scale), h = static_cast<int>(img.rows * scale);
  const int x0 = (W - w) / 2, y0 = (H - h) / 2;
  gl::BindFramebuffer(GL_READ_FRAMEBUFFER, r.present_fbo);
  gl::BindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  gl::Viewport(0, 0, W, H);
  gl::ClearColor(0, 0, 0, 1);
  gl::Clear(GL_COLOR_BUFFER_BIT);
  gl::BlitFramebuffer(0, 0, img.cols, img.rows, x0, y0 + h, x0 + w, y0, GL_COLOR_BUFFER_BIT,
                      GL_LINEAR);
  gl::BindFramebuffer(GL_FRAMEBUFFER, 0);
  context.swap_buffers();
  return gl::check_gl("renderer: present");
}

}  // namespace spidar::render
