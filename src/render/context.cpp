#include "spidar/render/context.hpp"

#define EGL_NO_X11  // keep X11 headers out of eglplatform.h
#include <EGL/egl.h>
#include <EGL/eglext.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <cstdio>
#include <cstdlib>
#include <mutex>

#include "gl_api.hpp"

namespace spidar::render {

void render_in_drawing_thread() { setenv("LP_NUM_THREADS", "0", 0); }
namespace {

constexpr const char* kMesaHint =
    "Mesa's EGL and llvmpipe come with libegl-mesa0 and libgl1-mesa-dri (scripts/install-deps)";

std::string egl_error_text() {
  char buf[32];
  std::snprintf(buf, sizeof buf, "EGL error 0x%04x", static_cast<unsigned>(eglGetError()));
  return buf;
}

void* egl_proc(const char* name) { return reinterpret_cast<void*>(eglGetProcAddress(name)); }
void* glfw_proc(const char* name) { return reinterpret_cast<void*>(glfwGetProcAddress(name)); }

std::string gl_string(GLenum name) {
  const GLubyte* s = gl::GetString(name);
  return s ? reinterpret_cast<const char*>(s) : "";
}

// GLFW is initialised once per process and terminated with the last window.
std::mutex g_glfw_mutex;
int g_glfw_windows = 0;
std::string g_glfw_error;

void glfw_error_callback(int code, const char* text) {
  g_glfw_error = "GLFW error " + std::to_string(code) + ": " + (text ? text : "");
}

}  // namespace

struct Context::Impl {
  ContextKind kind = ContextKind::kHeadless;
  // Headless.
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext egl_context = EGL_NO_CONTEXT;
  // Window.
  GLFWwindow* window = nullptr;
  std::string renderer, version;

  ~Impl() {
    if (egl_context != EGL_NO_CONTEXT) {
      if (eglGetCurrentContext() == egl_context)
        eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      eglDestroyContext(display, egl_context);
      // The display stays initialised: eglTerminate would pull it from under any other context
      // of this process, and eglInitialize on it again is cheap and idempotent.
    }
    if (window) {
      std::lock_guard lock(g_glfw_mutex);
      glfwDestroyWindow(window);
      if (--g_glfw_windows == 0) glfwTerminate();
    }
  }
};

Context::Context(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Context::~Context() = default;

Result<std::unique_ptr<Context>> Context::create_headless() {
  auto impl = std::make_unique<Impl>();
  impl->kind = ContextKind::kHeadless;
  const char* client_ext = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  const std::string exts = client_ext ? client_ext : "";
  if (exts.find("EGL_MESA_platform_surfaceless") == std::string::npos)
    return Error{"headless OpenGL: EGL has no EGL_MESA_platform_surfaceless (client extensions: '" +
                 exts + "'); " + kMesaHint};
  auto get_platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
      eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (!get_platform_display)
    return Error{std::string("headless OpenGL: eglGetPlatformDisplayEXT missing; ") + kMesaHint};
  impl->display = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (impl->display == EGL_NO_DISPLAY)
    return Error{"headless OpenGL: no surfaceless EGL display (" + egl_error_text() + "); " +
                 kMesaHint};
  EGLint major = 0, minor = 0;
  if (!eglInitialize(impl->display, &major, &minor))
    return Error{"headless OpenGL: eglInitialize failed (" + egl_error_text() + "); " + kMesaHint};
  if (!eglBindAPI(EGL_OPENGL_API))
    return Error{"headless OpenGL: eglBindAPI(EGL_OPENGL_API) failed (" + egl_error_text() +
                 "): this EGL offers no desktop OpenGL"};
  // EGL_SURFACE_TYPE 0: any config (the default, EGL_WINDOW_BIT, matches none on surfaceless).
  const EGLint config_attribs[] = {EGL_SURFACE_TYPE, 0, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
  EGLConfig config = nullptr;
  EGLint n = 0;
  if (!eglChooseConfig(impl->display, config_attribs, &config, 1, &n) || n < 1)
    return Error{"headless OpenGL: no EGL config with desktop OpenGL (" + egl_error_text() + ")"};
  const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3,
                                    EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                    EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  impl->egl_context = eglCreateContext(impl->display, config, EGL_NO_CONTEXT, context_attribs);
  if (impl->egl_context == EGL_NO_CONTEXT)
    return Error{"headless OpenGL: cannot create a GL 3.3 core context (" + egl_error_text() + ")"};
  if (!eglMakeCurrent(impl->display, EGL_NO_SURFACE, EGL_NO_SURFACE, impl->egl_context))
    return Error{"headless OpenGL: eglMakeCurrent without a surface failed (" + egl_error_text() +
                 "); the driver lacks EGL_KHR_surfaceless_context"};
  if (auto s = gl::load_gl_api(&egl_proc); !s) return s.error();
  impl->renderer = gl_string(GL_RENDERER);
  impl->version = gl_string(GL_VERSION);
  return std::unique_ptr<Context>(new Context(std::move(impl)));
}

Result<std::unique_ptr<Context>> Context::create_window(const WindowParams& params) {
  if (params.width <= 0 || params.height <= 0)
    return Error{"window: size must be positive, got " + std::to_string(params.width) + "x" +
                 std::to_string(params.height)};
  if (!std::getenv("DISPLAY") && !std::getenv("WAYLAND_DISPLAY"))
    return Error{"window: no window system (DISPLAY and WAYLAND_DISPLAY are unset); use the "
                 "headless context, or run under a desktop session"};
  auto impl = std::make_unique<Impl>();
  impl->kind = ContextKind::kWindow;
  {
    std::lock_guard lock(g_glfw_mutex);
    glfwSetErrorCallback(&glfw_error_callback);
    if (g_glfw_windows == 0 && !glfwInit())
      return Error{"window: glfwInit failed: " + g_glfw_error};
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    impl->window =
        glfwCreateWindow(params.width, params.height, params.title.c_str(), nullptr, nullptr);
    if (!impl->window) {
      if (g_glfw_windows == 0) glfwTerminate();
      return Error{"window: cannot create a " + std::to_string(params.width) + "x" +
                   std::to_string(params.height) + " window with GL 3.3 core: " + g_glfw_error};
    }
    ++g_glfw_windows;
  }
  glfwMakeContextCurrent(impl->window);
  glfwSwapInterval(params.vsync ? 1 : 0);
  if (auto s = gl::load_gl_api(&glfw_proc); !s) return s.error();
  impl->renderer = gl_string(GL_RENDERER);
  impl->version = gl_string(GL_VERSION);
  return std::unique_ptr<Context>(new Context(std::move(impl)));
}

ContextKind Context::kind() const { return impl_->kind; }

Status Context::make_current() {
  if (impl_->kind == ContextKind::kWindow) {
    glfwMakeContextCurrent(impl_->window);
    return Ok{};
  }
  if (!eglMakeCurrent(impl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, impl_->egl_context))
    return Error{"headless OpenGL: eglMakeCurrent failed (" + egl_error_text() + ")"};
  return Ok{};
}

const std::string& Context::gl_renderer() const { return impl_->renderer; }
const std::string& Context::gl_version() const { return impl_->version; }

void* Context::native_window() const { return impl_->window; }

bool Context::should_close() const {
  return impl_->window != nullptr && glfwWindowShouldClose(impl_->window);
}
void Context::poll_events() {
  if (impl_->window) glfwPollEvents();
}
void Context::swap_buffers() {
  if (impl_->window) glfwSwapBuffers(impl_->window);
}
int Context::framebuffer_width() const {
  int w = 0, h = 0;
  if (impl_->window) glfwGetFramebufferSize(impl_->window, &w, &h);
  return w;
}
int Context::framebuffer_height() const {
  int w = 0, h = 0;
  if (impl_->window) glfwGetFramebufferSize(impl_->window, &w, &h);
  return h;
}

}  // namespace spidar::render
