#pragma once
/// An OpenGL 3.3 core context: headless (EGL on Mesa's surfaceless platform: no display, no GPU
/// needed, llvmpipe in CI) or a GLFW window. The renderer does not care which; it draws into its
/// own offscreen targets and, for a window, presents a finished image (Renderer::present).
///
/// A context is current on the thread that created it; GL calls must come from that thread (use
/// make_current() after moving work to another thread). No GL or EGL types appear here.
#include <memory>
#include <string>

#include "spidar/core/result.hpp"

namespace spidar::render {

enum class ContextKind { kHeadless, kWindow };

/// Asks Mesa's software rasteriser (llvmpipe, the headless GL here) to render in the thread that
/// draws instead of a pool shared by every context of the process (LP_NUM_THREADS=0), unless the
/// environment already sets LP_NUM_THREADS. Threads that each render (the simulated camera, the
/// frame thread, the output thread) then do so at their own priority rather than queueing behind
/// one another. Takes effect only if called before the process's first GL context.
void render_in_drawing_thread();

struct WindowParams {
  int width = 640;   ///< client area [px]
  int height = 480;  ///< [px]
  std::string title = "spidar-mr";
  bool vsync = true;
};

class Context {
 public:
  /// EGL surfaceless context (eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA)). Works
  /// with no DISPLAY. Error says which EGL step failed and which packages provide it.
  static Result<std::unique_ptr<Context>> create_headless();
  /// A GLFW window with a GL 3.3 core context. Error when there is no window system (e.g. no
  /// DISPLAY) or the driver offers no GL 3.3 core.
  static Result<std::unique_ptr<Context>> create_window(const WindowParams& params = {});

  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  ContextKind kind() const;
  /// Makes this context current on the calling thread.
  Status make_current();
  /// GL_RENDERER and GL_VERSION strings, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)", "4.5 (Core ...)".
  const std::string& gl_renderer() const;
  const std::string& gl_version() const;

  /// Window only (headless: no-ops, should_close() false, size 0×0).
  bool should_close() const;
  void poll_events();
  void swap_buffers();
  /// The window's GLFWwindow* (for GUI toolkits such as Dear ImGui's GLFW backend); null when
  /// headless.
  void* native_window() const;
  /// Size of the window's default framebuffer [px].
  int framebuffer_width() const;
  int framebuffer_height() const;

 private:
  struct Impl;
  explicit Context(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace spidar::render
