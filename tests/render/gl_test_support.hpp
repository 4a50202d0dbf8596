#pragma once
// One headless GL context for the whole test binary. Tests that need GL call gl_context() and
// fail (not skip) with the context's error when there is none: CI installs Mesa
// (scripts/install-deps), so a missing GL is a broken set-up, not a reason to pass.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "spidar/render/context.hpp"

namespace spidar::render::test {

struct GlState {
  std::unique_ptr<Context> context;
  std::string error;
};

inline GlState& gl_state() {
  static GlState state = [] {
    GlState s;
    auto r = Context::create_headless();
    if (r) s.context = std::move(r).value();
    else s.error = r.error().message;
    return s;
  }();
  return state;
}

/// The shared context, or nullptr (then gl_error() says why).
inline Context* gl_context() { return gl_state().context.get(); }
inline const std::string& gl_error() { return gl_state().error; }

#define SPIDAR_REQUIRE_GL()                                                                  \
  ASSERT_NE(::spidar::render::test::gl_context(), nullptr)                                  \
      << "no headless OpenGL (EGL surfaceless Mesa); install it with scripts/install-deps: " \
      << ::spidar::render::test::gl_error()

}  // namespace spidar::render::test
