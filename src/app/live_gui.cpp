#include "live_gui.hpp"

#include "live_exit.hpp"

#include <GL/gl.h>
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cmath>
#include <fstream>
#include <sstream>
#include <iostream>
#include <opencv2/imgproc.hpp>
#include <thread>

#include "cli_support.hpp"
#include "gui_camera_calibration.hpp"
#include "spidar/core/units.hpp"
#include "spidar/core/clock.hpp"
#include "spidar/core/config.hpp"
#include "spidar/core/file_read.hpp"
#include "spidar/hand/render_geometry.hpp"
#include "spidar/render/overlay.hpp"
#include "spidar/render/video_output.hpp"
#include "spidar/device/unwrapped_counts.hpp"
#include "spidar/strings/calibration.hpp"
#include "spidar/strings/device_config_write.hpp"
#include "spidar/strings/stability_check.hpp"
#include "spidar/session/json_text.hpp"

#ifndef GL_BGR
#define GL_BGR 0x80E0
#endif
#ifndef GL_FRAMEBUFFER
#define GL_FRAMEBUFFER 0x8D40
#endif

namespace spidar::app {
namespace {

/// The few GL entry points the GUI uses itself (textures for the views, the screenshot), loaded
/// through GLFW like the renderer's own table: nothing links libGL directly.
struct Gl {
  void(APIENTRY* GenTextures)(GLsizei, GLuint*) = nullptr;
  void(APIENTRY* DeleteTextures)(GLsizei, const GLuint*) = nullptr;
  void(APIENTRY* BindTexture)(GLenum, GLuint) = nullptr;
  void(APIENTRY* TexParameteri)(GLenum, GLenum, GLint) = nullptr;
  void(APIENTRY* TexImage2D)(GLenum, GLint, GLint, GLsizei, GLsizei, GLint, GLenum, GLenum, const void*) = nullptr;
  void(APIENTRY* PixelStorei)(GLenum, GLint) = nullptr;
  void(APIENTRY* BindFramebuffer)(GLenum, GLuint) = nullptr;
  void(APIENTRY* Viewport)(GLint, GLint, GLsizei, GLsizei) = nullptr;
  void(APIENTRY* ClearColor)(GLfloat, GLfloat, GLfloat, GLfloat) = nullptr;
  void(APIENTRY* Clear)(GLbitfield) = nullptr;
  void(APIENTRY* ReadPixels)(GLint, GLint, GLsizei, GLsizei, GLenum, GLenum, void*) = nullptr;
  void(APIENTRY* ReadBuffer)(GLenum) = nullptr;

  bool load() {
    auto get = [](auto& fn, const char* name) {
      fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(glfwGetProcAddress(name));
      return fn != nullptr;
    };
    return get(GenTextures, "glGenTextures") && get(DeleteTextures, "glDeleteTextures") &&
           get(BindTexture, "glBindTexture") && get(TexParameteri, "glTexParameteri") &&
           get(TexImage2D, "glTexImage2D") && get(PixelStorei, "glPixelStorei") &&
           get(BindFramebuffer, "glBindFramebuffer") && get(Viewport, "glViewport") &&
           get(ClearColor, "glClearColor") && get(Clear, "glClear") && get(ReadPixels, "glReadPixels") &&
           get(ReadBuffer, "glReadBuffer");
  }
};

enum class View { kComposite, kVirtual, kCamera, kMatte, kOverlay };
constexpr const char* kViewNames[] = {"composite", "virtual only", "camera only", "matte",
                                      "virtual-hand overlay"};

/// One BGR image as a GL texture.
class Texture {
 public:
  explicit Texture(const Gl& gl) : gl_(gl) {}
  ~Texture() {
    if (id_) gl_.DeleteTextures(1, &id_);
  }
  void upload(const cv::Mat& bgr) {
    if (bgr.empty()) return;
    cv::Mat c = bgr.isContinuous() ? bgr : bgr.clone();
    if (!id_) gl_.GenTextures(1, &id_);
    gl_.BindTexture(GL_TEXTURE_2D, id_);
    gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl_.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    gl_.TexImage2D(GL_TEXTURE_2D, 0, GL_RGB, c.cols, c.rows, 0, GL_BGR, GL_UNSIGNED_BYTE, c.data);
    w_ = c.cols;
    h_ = c.rows;
  }
  ImTextureID id() const { return reinterpret_cast<ImTextureID>(static_cast<std::intptr_t>(id_)); }
  bool empty() const { return id_ == 0; }
  int width() const { return w_; }
  int height() const { return h_; }

 private:
  const Gl& gl_;
  GLuint id_ = 0;
  int w_ = 0, h_ = 0;
};

/// The image a view shows, from the last processed frame.
cv::Mat view_image(View view, const session::LiveSession& s) {
  const pipeline::FrameResult& r = s.result();
  switch (view) {
    case View::kComposite:
      return r.composite;
    case View::kVirtual:
      return r.virt.colour;
    case View::kCamera:
      return s.camera_image();
    case View::kMatte: {
      if (r.key.alpha.empty()) return {};
      cv::Mat g, bgr;
      r.key.alpha.convertTo(g, CV_8U, 255.0);
      cv::cvtColor(g, bgr, cv::COLOR_GRAY2BGR);
      return bgr;
    }
    case View::kOverlay: {
      if (r.composite.empty()) return {};
      cv::Mat out = r.composite.clone();
      for (int h = 0; h < 2; ++h)
        render::draw_hand_wireframe(out, s.camera(), hand::hand_render_shapes(s.models()[h], r.hands[h]));
      const auto& m = s.measured();
      std::vector<Vec3> p, f;
      for (int i = 0; i < m.finger_count; ++i) {
        p.push_back(device::fingertip_position(m, i));
        f.push_back(device::fingertip_force(m, i));
      }
      render::draw_force_arrows(out, s.camera(), p, f);
      return out;
    }
  }
  return {};
}

/// The last `n` values of a history field, as floats for ImGui's plots.
template <typename F>
std::vector<float> series(const session::HistoryRing<session::LiveFrameStats>& h, std::size_t n, F field) {
  std::vector<float> v;
  const std::size_t start = h.size() > n ? h.size() - n : 0;
  v.reserve(h.size() - start);
  for (std::size_t i = start; i < h.size(); ++i) v.push_back(static_cast<float>(field(h[i])));
  return v;
}

void plot(const char* label, const std::vector<float>& v, const char* fmt, float lo, float hi) {
  char overlay[64] = "";
  if (!v.empty()) std::snprintf(overlay, sizeof overlay, fmt, v.back());
  ImGui::PlotLines(label, v.data(), static_cast<int>(v.size()), 0, overlay, lo, hi, ImVec2(0, 60));
}

void device_panel(session::LiveSession& s) {
  const strings::DeviceConfig& cfg = s.device_config();
  const device::FingertipSample& m = s.measured();
  const auto limits = cfg.effective_limits();
  const std::uint32_t faults = s.servo().faults();
  if (faults != 0) {
    ImGui::TextColored(ImVec4(1, 0.3f, 0.3f, 1), "FAULT: %s", device::fault_names(faults).c_str());
    if (ImGui::Button("Reset faults")) s.servo().reset_faults();
  } else {
    ImGui::TextColored(ImVec4(0.4f, 1, 0.4f, 1), "servo running, no faults");
  }
  ImGui::SameLine();
  ImGui::PushStyleColor(ImGuiCol_Button, ImVec4(0.8f, 0.1f, 0.1f, 1));
  if (ImGui::Button("EMERGENCY STOP (space)")) s.servo().emergency_stop();
  ImGui::PopStyleColor();

  const auto& h = s.history();
  plot("loop rate [Hz]", series(h, 300, [](const session::LiveFrameStats& x) { return x.servo_rate_hz; }), "%.0f Hz",
       0.0f, static_cast<float>(s.config().rate_hz * 1.2));
  plot("jitter max [us]", series(h, 300, [](const session::LiveFrameStats& x) { return x.servo_jitter_max_us; }),
       "%.0f us", 0.0f, FLT_MAX);

  if (ImGui::BeginTable("strings", 4, ImGuiTableFlags_SizingStretchProp)) {
    ImGui::TableSetupColumn("finger");
    ImGui::TableSetupColumn("lengths [m]");
    ImGui::TableSetupColumn("tensions [N]");
    ImGui::TableSetupColumn("force [N] (x right, z up)");
    ImGui::TableHeadersRow();
    for (int f = 0; f < m.finger_count && f < static_cast<int>(cfg.fingers.size()); ++f) {
      const auto& g = cfg.fingers[f].geometry;
      const Vec3 force = device::fingertip_force(m, f);
      const auto lengths = strings::string_lengths(g, device::fingertip_position(m, f));
      const int first = cfg.first_string(f);
      ImGui::TableNextRow();
      ImGui::TableSetColumnIndex(0);
      ImGui::TextUnformatted(cfg.fingers[f].name.c_str());
      ImGui::TableSetColumnIndex(1);
      for (int i = 0; i < g.n; ++i) {
        char txt[32];
        std::snprintf(txt, sizeof txt, "%.3f", lengths[i]);
        ImGui::ProgressBar(static_cast<float>(lengths[i] / 0.8), ImVec2(-1, 0), txt);
      }
      ImGui::TableSetColumnIndex(2);
      for (int i = 0; i < g.n; ++i) {
        // What the servo cycle solved and sent (0 N while the motors are held at their minimum).
        const int k = first + i;
        const double t = k < m.string_count ? m.tension[static_cast<std::size_t>(k)] : 0.0;
        char txt[32];
        std::snprintf(txt, sizeof txt, "%.2f", t);
        ImGui::ProgressBar(static_cast<float>(t / limits.t_max), ImVec2(-1, 0), txt);
      }
      ImGui::TableSetColumnIndex(3);
      // The force as an arrow seen from the user (x right, z up), 10 px per newton, and its size.
      const ImVec2 c0 = ImGui::GetCursorScreenPos();
      const float size = 48;
      ImDrawList* dl = ImGui::GetWindowDrawList();
      const ImVec2 centre(c0.x + size / 2, c0.y + size / 2);
      dl->AddRect(c0, ImVec2(c0.x + size, c0.y + size), IM_COL32(90, 90, 90, 255));
      const float sx = std::clamp(static_cast<float>(force.x() * 10), -size / 2, size / 2);
      const float sz = std::clamp(static_cast<float>(-force.z() * 10), -size / 2, size / 2);
      const ImVec2 tip(centre.x + sx, centre.y + sz);
      dl->AddLine(centre, tip, IM_COL32(255, 220, 0, 255), 2.0f);
      dl->AddCircleFilled(tip, 3.0f, IM_COL32(255, 220, 0, 255));
      ImGui::Dummy(ImVec2(size, size));
      ImGui::SameLine();
      ImGui::Text("%.2f N", force.norm());
    }
    ImGui::EndTable();
  }
}

void registration_panel(const session::LiveSession& s) {
  const auto& h = s.history();
  if (h.empty()) {
    ImGui::TextUnformatted("waiting for the first frame");
    return;
  }
  const session::LiveFrameStats& last = h.back();
  ImGui::Text("frames %llu of %llu filmed   latency %.0f ms   pipeline %.0f ms",
              static_cast<unsigned long long>(s.frames()), static_cast<unsigned long long>(s.camera_frames()),
              last.latency_ms, last.pipeline_ms);
  ImGui::Text("iterations: left %d, right %d", last.iterations[0], last.iterations[1]);
  plot("IoU vs matte", series(h, 300, [](const session::LiveFrameStats& x) { return x.iou; }), "%.3f", 0.0f, 1.0f);
  static const char* kTerms[] = {"fingertip", "wrist", "joint-ball", "silhouette", "prior"};
  for (int t = 0; t < 5; ++t) {
    auto v = series(h, 300, [t](const session::LiveFrameStats& x) {
      double sum = 0;
      for (const auto& term : x.terms) {
        const double a[5] = {term.fingertip, term.wrist, term.joint_ball, term.silhouette, term.prior};
        sum += a[t];
      }
      return sum;
    });
    plot(kTerms[t], v, "%.3g", 0.0f, FLT_MAX);
  }
  plot("iterations", series(h, 300, [](const session::LiveFrameStats& x) { return x.iterations[0] + x.iterations[1]; }),
       "%.0f", 0.0f, FLT_MAX);
}

void scene_panel(session::LiveSession& s) {
  const auto st = s.cube_status();
  if (!s.cube().has_cube()) ImGui::TextUnformatted("no Rubik's cube in this scene");
  if (st) {
    ImGui::Text("cube: %s, %d turns, lift %.1f mm, top layer %.0f deg, %d contacts",
                st->solved ? "SOLVED" : "scrambled", st->turns, st->lift * 1e3, st->u_angle * 180 / units::kPi,
                st->contacts);
  }
  if (ImGui::Button("Reset scene")) s.cube().request_reset();
  ImGui::SameLine();
  if (ImGui::Button("Scramble (20 turns)")) s.cube().request_scramble(20);
  ImGui::Text("session %.1f s", s.seconds());
}

/// The simulated user's hands under interactive control: keys move and close them, sliders too.
void hands_panel(session::InteractiveHands& ih, GLFWwindow* window, double dt) {
  session::HandControls c = ih.controls();
  struct Keys {
    int away, toward, left, right, up, down, yaw_left, yaw_right, close, open;
  };
  static constexpr Keys kKeys[2] = {
      {GLFW_KEY_W, GLFW_KEY_S, GLFW_KEY_A, GLFW_KEY_D, GLFW_KEY_R, GLFW_KEY_F, GLFW_KEY_Q, GLFW_KEY_E,
       GLFW_KEY_Z, GLFW_KEY_X},
      {GLFW_KEY_UP, GLFW_KEY_DOWN, GLFW_KEY_LEFT, GLFW_KEY_RIGHT, GLFW_KEY_PAGE_UP, GLFW_KEY_PAGE_DOWN,
       GLFW_KEY_COMMA, GLFW_KEY_PERIOD, GLFW_KEY_N, GLFW_KEY_M}};
  if (!ImGui::GetIO().WantCaptureKeyboard) {
    auto key = [&](int k) { return glfwGetKey(window, k) == GLFW_PRESS ? 1.0 : 0.0; };
    const double speed = 0.08 * dt, turn = 1.0 * dt, grip = 1.5 * dt;  // m/s, rad/s, 1/s
    for (int h = 0; h < 2; ++h) {
      const Keys& k = kKeys[h];
      c[h].offset_W[0] += speed * (key(k.right) - key(k.left));
      c[h].offset_W[1] += speed * (key(k.away) - key(k.toward));
      c[h].offset_W[2] += speed * (key(k.up) - key(k.down));
      c[h].yaw += turn * (key(k.yaw_left) - key(k.yaw_right));
      c[h].closeness += grip * (key(k.close) - key(k.open));
    }
  }
  ImGui::TextUnformatted("left:  W/S away/toward, A/D left/right, R/F up/down, Q/E turn, Z close, X open");
  ImGui::TextUnformatted("right: arrows, PageUp/PageDown up/down, comma/period turn, N close, M open");
  const char* names[2] = {"left", "right"};
  for (int h = 0; h < 2; ++h) {
    ImGui::PushID(h);
    float off[3] = {static_cast<float>(c[h].offset_W[0]), static_cast<float>(c[h].offset_W[1]),
                    static_cast<float>(c[h].offset_W[2])};
    float yaw = static_cast<float>(c[h].yaw * 180 / units::kPi), close = static_cast<float>(c[h].closeness);
    ImGui::Text("%s hand", names[h]);
    if (ImGui::SliderFloat3("offset x y z [m]", off, -0.25f, 0.25f, "%.3f"))
      for (int i = 0; i < 3; ++i) c[h].offset_W[i] = off[i];
    if (ImGui::SliderFloat("turn [deg]", &yaw, -180.f, 180.f, "%.0f")) c[h].yaw = yaw * units::kPi / 180;
    if (ImGui::SliderFloat("closed", &close, 0.f, 1.f, "%.2f")) c[h].closeness = close;
    ImGui::PopID();
  }
  ih.set(c);
}

/// Pole calibration in the window, finger by finger: the fingertip's counts (unwrapped as the
/// servo cycle does) must hold still for a moment (strings::StabilityCheck), then the offsets are
/// computed and may be written into the device config (the previous version kept). The running
/// session keeps its calibration until restarted.
class CalibrationPanel {
 public:
  void draw(session::LiveSession& s) {
    const strings::DeviceConfig& cfg = s.device_config();
    std::vector<const char*> names;
    for (const auto& f : cfg.fingers) names.push_back(f.name.c_str());
    ImGui::Combo("finger", &finger_, names.data(), static_cast<int>(names.size()));
    const strings::FingerConfig& fc = cfg.fingers[finger_];
    if (!counts_)
      counts_ = std::make_unique<device::UnwrappedCounts>(cfg.string_count(), cfg.counter_bits);
    const auto rec = s.newest_device_cycle();
    if (rec) counts_->update(rec->reading);
    if (ImGui::Button("Start pole sample")) {
      strings::StabilityParams p;
      p.hold_s = 1.0;
      p.near_m = 1e9;  // before a first calibration the counters may be zeroed anywhere
      check_ = std::make_unique<strings::StabilityCheck>(fc, cfg.p_W_centre, p);
      check_finger_ = finger_;
      result_.clear();
      message_.clear();
    }
    if (check_ && !check_->ready()) {
      if (rec) {
        check_->update(core::ns_to_s(rec->reading.host_time_ns),
                       counts_->counts(cfg.first_string(check_finger_), cfg.fingers[check_finger_].geometry.n));
        if (check_->ready()) {
          sample_ = check_->sample();
          auto ch = strings::pole_calibrate(cfg.fingers[check_finger_].geometry, cfg.fingers[check_finger_].channels,
                                            sample_, cfg.p_W_centre);
          if (ch) result_ = *ch;
          else message_ = ch.error().message;
        }
      }
      ImGui::Text("%s: touch the pole tip with the fingertip cap and hold still",
                  cfg.fingers[check_finger_].name.c_str());
      ImGui::ProgressBar(static_cast<float>(check_->held_s() / 1.0), ImVec2(-1, 0), "holding still");
      ImGui::Text("strings moving %.2f mm", check_->spread_m() * 1e3);
    }
    if (!result_.empty()) {
      const auto& old = cfg.fingers[check_finger_].channels;
      ImGui::Text("%s sampled: length at zero [m]", cfg.fingers[check_finger_].name.c_str());
      for (std::size_t i = 0; i < result_.size(); ++i)
        ImGui::Text("  string %zu: %.4f -> %.4f", i + 1, old[i].length_at_zero, result_[i].length_at_zero);
      if (ImGui::Button("Write to the device config")) {
        try {
          const std::string text = core::read_file_bounded(cfg.source, core::kMaxConfigFileBytes, "a config file");
          const std::string out = strings::with_finger_channels(text, cfg.source, cfg.fingers[check_finger_].name,
                                                                result_, false, "pole calibration (GUI)");
          const std::string backup = strings::write_device_config(cfg.source, out);
          message_ = "wrote " + cfg.source + " (previous: " + backup + "); restart run to use it";
        } catch (const std::exception& e) {
          message_ = e.what();
        }
        result_.clear();
        check_.reset();
      }
    }
    if (!message_.empty()) ImGui::TextWrapped("%s", message_.c_str());
  }

 private:
  int finger_ = 0, check_finger_ = 0;
  std::unique_ptr<strings::StabilityCheck> check_;
  std::unique_ptr<device::UnwrappedCounts> counts_;
  std::vector<std::int64_t> sample_;
  std::vector<strings::EncoderChannel> result_;
  std::string message_;
};

cv::Mat read_default_framebuffer(const Gl& gl, int w, int h) {
  cv::Mat img(h, w, CV_8UC3);
  gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
  gl.ReadBuffer(GL_BACK);
  gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
  gl.ReadPixels(0, 0, w, h, GL_BGR, GL_UNSIGNED_BYTE, img.data);
  cv::Mat flipped;
  cv::flip(img, flipped, 0);  // GL rows go bottom-up
  return flipped;
}

}  // namespace

int run_gui(const session::LiveConfig& cfg, const session::LiveSessionOptions& options, double seconds,
            const std::string& screenshot, std::atomic<int>& signal) {
  render::WindowParams wp;
  wp.width = cfg.window_width;
  wp.height = cfg.window_height;
  wp.title = "spidar-mr: " + cfg.source;
  auto ctx_r = render::Context::create_window(wp);
  if (!ctx_r)
    throw UsageError("window: " + ctx_r.error().message +
                     " (no display? run with --headless, or under xvfb-run -a)");
  auto context = std::move(ctx_r).value();
  auto* window = static_cast<GLFWwindow*>(context->native_window());
  Gl gl;
  if (!gl.load()) throw SpidarError("window: GL entry points missing (glfwGetProcAddress)");

  session::LiveSessionOptions no_warm_up = options;  // the window is up: show frames at once
  no_warm_up.warm_up = false;
  auto session = session::LiveSession::create(cfg, *context, no_warm_up);
  // Sticky keys: a tap shorter than one GUI frame (the space bar's emergency stop above all) is
  // still seen by the next glfwGetKey.
  glfwSetInputMode(window, GLFW_STICKY_KEYS, GLFW_TRUE);

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini next to the user's files
  ImGui::StyleColorsDark();
  if (!ImGui_ImplGlfw_InitForOpenGL(window, true) || !ImGui_ImplOpenGL3_Init("#version 330")) {
    ImGui::DestroyContext();
    throw SpidarError("window: Dear ImGui's GLFW/OpenGL3 backends failed to initialise");
  }
  struct ImGuiScope {
    ~ImGuiScope() {
      ImGui_ImplOpenGL3_Shutdown();
      ImGui_ImplGlfw_Shutdown();
      ImGui::DestroyContext();
    }
  } imgui_scope;

  std::cerr << "spidar-mr run: " << cfg.source << ": window " << cfg.window_width << "x"
            << cfg.window_height << "; close it, Ctrl-C or wait to stop\n";

  Texture tex(gl);
  View view = View::kComposite;
  bool new_frame = false;
  cv::Mat shot;
  double last_ui_s = 0;
  CalibrationPanel calibration;
  CameraCalibrationPanel camera_calibration;
  std::string ended_by = "seconds";
  session->start();
  while (true) {
    if (signal.load() != 0) {
      ended_by = signal.load() == SIGINT ? "SIGINT" : "SIGTERM";
      break;
    }
    if (context->should_close()) {
      ended_by = "window closed";
      break;
    }
    if (seconds > 0 && session->seconds() >= seconds) break;
    if (!session->running()) {
      ended_by = session->camera_ended() ? "camera ended" : "device stopped";
      break;
    }
    context->poll_events();
    // The space bar stops the device from anywhere in the window, whatever has the keyboard.
    if (glfwGetKey(window, GLFW_KEY_SPACE) == GLFW_PRESS) session->servo().emergency_stop();
    // Take every frame that is ready (the GUI draws at most at the display's rate).
    for (int k = 0; k < 4 && session->step(); ++k) new_frame = true;
    if (new_frame) {
      tex.upload(view_image(view, *session));
      new_frame = false;
    }

    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    const float W = static_cast<float>(context->framebuffer_width());
    const float vw = static_cast<float>(cfg.width), vh = static_cast<float>(cfg.height);
    ImGui::SetNextWindowPos(ImVec2(0, 0), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(vw + 16, vh + 60), ImGuiCond_FirstUseEver);
    ImGui::Begin("Mixed-reality view");
    int v = static_cast<int>(view);
    if (ImGui::Combo("view", &v, kViewNames, IM_ARRAYSIZE(kViewNames))) {
      view = static_cast<View>(v);
      tex.upload(view_image(view, *session));
    }
    if (!tex.empty()) {
      const ImVec2 avail = ImGui::GetContentRegionAvail();
      const float tw = static_cast<float>(tex.width()), th = static_cast<float>(tex.height());
      const float scale = std::max(0.1f, std::min(avail.x / tw, avail.y / th));
      const ImVec2 image_min = ImGui::GetCursorScreenPos();
      ImGui::Image(tex.id(), ImVec2(tw * scale, th * scale));
      camera_calibration.on_view(*session, image_min, scale * tw / vw);
    } else {
      ImGui::TextUnformatted("waiting for the camera");
    }
    ImGui::End();

    ImGui::SetNextWindowPos(ImVec2(vw + 20, 0), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(std::max(300.0f, W - vw - 24), vh + 60), ImGuiCond_FirstUseEver);
    ImGui::Begin("Device");
    device_panel(*session);
    ImGui::End();

    ImGui::SetNextWindowPos(ImVec2(0, vh + 64), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(vw + 16, 420), ImGuiCond_FirstUseEver);
    ImGui::Begin("Registration");
    registration_panel(*session);
    ImGui::End();

    ImGui::SetNextWindowPos(ImVec2(vw + 20, vh + 64), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(std::max(300.0f, W - vw - 24), 200), ImGuiCond_FirstUseEver);
    ImGui::Begin("Scene");
    scene_panel(*session);
    ImGui::End();

    ImGui::SetNextWindowPos(ImVec2(vw + 20, vh + 268), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(std::max(300.0f, W - vw - 24), 200), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowCollapsed(true, ImGuiCond_FirstUseEver);
    ImGui::Begin("Strings calibration");
    calibration.draw(*session);
    ImGui::End();

    ImGui::SetNextWindowPos(ImVec2(vw + 20, vh + 288), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(std::max(300.0f, W - vw - 24), 260), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowCollapsed(true, ImGuiCond_FirstUseEver);
    ImGui::Begin("Camera calibration");
    camera_calibration.draw(*session);
    ImGui::End();

    if (session::InteractiveHands* ih = session->interactive()) {
      ImGui::SetNextWindowPos(ImVec2(vw + 20, vh + 312), ImGuiCond_FirstUseEver);
      ImGui::SetNextWindowSize(ImVec2(std::max(300.0f, W - vw - 24), 190), ImGuiCond_FirstUseEver);
      ImGui::Begin("Hands (interactive)");
      const double now = session->seconds();
      hands_panel(*ih, window, std::clamp(now - last_ui_s, 0.0, 0.1));
      last_ui_s = now;
      ImGui::End();
    }

    ImGui::Render();
    const int fw = context->framebuffer_width(), fh = context->framebuffer_height();
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.Viewport(0, 0, fw, fh);
    gl.ClearColor(0.08f, 0.08f, 0.1f, 1.0f);
    gl.Clear(GL_COLOR_BUFFER_BIT);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    // For --screenshot: the last drawn frame, read before the swap (the back buffer is then
    // undefined), written once the loop ends.
    if (!screenshot.empty()) shot = read_default_framebuffer(gl, fw, fh);
    context->swap_buffers();
  }
  session->stop();
  if (!screenshot.empty()) {
    if (shot.empty()) throw SpidarError("--screenshot: the window never drew a frame");
    if (auto w = render::write_png(screenshot, shot); !w) throw SpidarError(w.error().message);
  }
  const auto st = session->servo().stats();
  nlohmann::json summary = {{"ended_by", ended_by},
                            {"frames", session->frames()},
                            {"servo_rate_hz", st.rate_hz},
                            {"faults", device::fault_names(st.faults)}};
  if (session::InteractiveHands* ih = session->interactive()) {
    // Where the keys and sliders left the hands (left, right).
    for (const session::HandControl& c : ih->controls())
      summary["hands"].push_back({{"offset_m", c.offset_W}, {"yaw_rad", c.yaw}, {"closeness", c.closeness}});
  }
  std::cout << session::json_text(summary) << "\n";
  return live_exit_code(*session, ended_by);
}

}  // namespace spidar::app
