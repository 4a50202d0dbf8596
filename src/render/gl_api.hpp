#pragma once
// The OpenGL 3.3 core entry points the renderer uses, as process-wide function pointers in
// spidar::render::gl (gl::Clear, gl::DrawElementsInstanced, ...), loaded by load_gl_api() through
// the current context's get-proc-address (eglGetProcAddress or glfwGetProcAddress).
//
// Why our own loader instead of libepoxy/glad: we need ~70 functions of one fixed version, the
// same table must work for an EGL surfaceless context and a GLFW (GLX) window, and libglvnd's
// dispatch stubs returned by either get-proc-address are valid for every context of the process,
// so loading once is enough. The types come from <GL/glcorearb.h> (libgl-dev).
#include <GL/glcorearb.h>

#include <string>

#include "spidar/core/result.hpp"

namespace spidar::render::gl {

#define SPIDAR_GL_FUNCTIONS(X)                                         \
  X(PFNGLGETSTRINGPROC, GetString)                                     \
  X(PFNGLGETINTEGERVPROC, GetIntegerv)                                 \
  X(PFNGLGETERRORPROC, GetError)                                       \
  X(PFNGLFINISHPROC, Finish)                                           \
  X(PFNGLCLEARPROC, Clear)                                             \
  X(PFNGLCLEARCOLORPROC, ClearColor)                                   \
  X(PFNGLCLEARBUFFERFVPROC, ClearBufferfv)                             \
  X(PFNGLCLEARBUFFERUIVPROC, ClearBufferuiv)                           \
  X(PFNGLCLEARBUFFERFIPROC, ClearBufferfi)                             \
  X(PFNGLVIEWPORTPROC, Viewport)                                       \
  X(PFNGLENABLEPROC, Enable)                                           \
  X(PFNGLDISABLEPROC, Disable)                                         \
  X(PFNGLDEPTHFUNCPROC, DepthFunc)                                     \
  X(PFNGLDEPTHMASKPROC, DepthMask)                                     \
  X(PFNGLCULLFACEPROC, CullFace)                                       \
  X(PFNGLFRONTFACEPROC, FrontFace)                                     \
  X(PFNGLPOLYGONMODEPROC, PolygonMode)                                 \
  X(PFNGLREADBUFFERPROC, ReadBuffer)                                   \
  X(PFNGLREADPIXELSPROC, ReadPixels)                                   \
  X(PFNGLPIXELSTOREIPROC, PixelStorei)                                 \
  X(PFNGLDRAWBUFFERSPROC, DrawBuffers)                                 \
  X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers)                         \
  X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers)                   \
  X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer)                         \
  X(PFNGLFRAMEBUFFERTEXTURE2DPROC, FramebufferTexture2D)               \
  X(PFNGLFRAMEBUFFERRENDERBUFFERPROC, FramebufferRenderbuffer)         \
  X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus)           \
  X(PFNGLBLITFRAMEBUFFERPROC, BlitFramebuffer)                         \
  X(PFNGLGENRENDERBUFFERSPROC, GenRenderbuffers)                       \
  X(PFNGLDELETERENDERBUFFERSPROC, DeleteRenderbuffers)                 \
  X(PFNGLBINDRENDERBUFFERPROC, BindRenderbuffer)                       \
  X(PFNGLRENDERBUFFERSTORAGEPROC, RenderbufferStorage)                 \
  X(PFNGLGENTEXTURESPROC, GenTextures)                                 \
  X(PFNGLDELETETEXTURESPROC, DeleteTextures)                           \
  X(PFNGLBINDTEXTUREPROC, BindTexture)                                 \
  X(PFNGLTEXIMAGE2DPROC, TexImage2D)                                   \
  X(PFNGLTEXSUBIMAGE2DPROC, TexSubImage2D)                             \
  X(PFNGLTEXPARAMETERIPROC, TexParameteri)                             \
  X(PFNGLGENBUFFERSPROC, GenBuffers)                                   \
  X(PFNGLDELETEBUFFERSPROC, DeleteBuffers)                             \
  X(PFNGLBINDBUFFERPROC, BindBuffer)                                   \
  X(PFNGLBUFFERDATAPROC, BufferData)                                   \
  X(PFNGLBUFFERSUBDATAPROC, BufferSubData)                             \
  X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays)                         \
  X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays)                   \
  X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                         \
  X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray)         \
  X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer)                 \
  X(PFNGLVERTEXATTRIBDIVISORPROC, VertexAttribDivisor)                 \
  X(PFNGLCREATESHADERPROC, CreateShader)                               \
  X(PFNGLSHADERSOURCEPROC, ShaderSource)                               \
  X(PFNGLCOMPILESHADERPROC, CompileShader)                             \
  X(PFNGLGETSHADERIVPROC, GetShaderiv)                                 \
  X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)                       \
  X(PFNGLDELETESHADERPROC, DeleteShader)                               \
  X(PFNGLCREATEPROGRAMPROC, CreateProgram)                             \
  X(PFNGLATTACHSHADERPROC, AttachShader)                               \
  X(PFNGLBINDATTRIBLOCATIONPROC, BindAttribLocation)                   \
  X(PFNGLBINDFRAGDATALOCATIONPROC, BindFragDataLocation)               \
  X(PFNGLLINKPROGRAMPROC, LinkProgram)                                 \
  X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                               \
  X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)                     \
  X(PFNGLDELETEPROGRAMPROC, DeleteProgram)                             \
  X(PFNGLUSEPROGRAMPROC, UseProgram)                                   \
  X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)                   \
  X(PFNGLUNIFORM1IPROC, Uniform1i)                                     \
  X(PFNGLUNIFORM1FPROC, Uniform1f)                                     \
  X(PFNGLUNIFORM3FPROC, Uniform3f)                                     \
  X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv)                       \
  X(PFNGLDRAWELEMENTSINSTANCEDPROC, DrawElementsInstanced)

#define SPIDAR_GL_DECLARE(type, name) inline type name = nullptr;
SPIDAR_GL_FUNCTIONS(SPIDAR_GL_DECLARE)
#undef SPIDAR_GL_DECLARE

/// A get-proc-address function: returns the entry point named e.g. "glClear", or null.
using ProcLoader = void* (*)(const char* name);

/// Loads every entry point above with `loader` (a context must be current). Error naming the
/// first missing function. Loading again is harmless.
Status load_gl_api(ProcLoader loader);

/// "GL_INVALID_OPERATION" etc. for a glGetError code.
std::string gl_error_name(GLenum code);

/// Ok, or an error naming `where` and every pending glGetError code (which it clears).
Status check_gl(const char* where);

}  // namespace spidar::render::gl
