#include "gl_api.hpp"

namespace spidar::render::gl {

Status load_gl_api(ProcLoader loader) {
#define SPIDAR_GL_LOAD(type, name)                                                            \
  name = reinterpret_cast<type>(loader("gl" #name));                                          \
  if (name == nullptr)                                                                        \
    return Error{"OpenGL: the driver has no gl" #name " (need OpenGL 3.3 core); is Mesa's " \
                 "libgl1-mesa-dri installed? (scripts/install-deps)"};
  SPIDAR_GL_FUNCTIONS(SPIDAR_GL_LOAD)
#undef SPIDAR_GL_LOAD
  return Ok{};
}

std::string gl_error_name(GLenum code) {
  switch (code) {
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
    default: return "GL error 0x" + std::to_string(code);
  }
}

Status check_gl(const char* where) {
  std::string errors;
  for (int i = 0; i < 16; ++i) {
    const GLenum code = GetError();
    if (code == GL_NO_ERROR) break;
    errors += (errors.empty() ? "" : ", ") + gl_error_name(code);
  }
  if (errors.empty()) return Ok{};
  return Error{std::string("OpenGL error in ") + where + ": " + errors};
}

}  // namespace spidar::render::gl
