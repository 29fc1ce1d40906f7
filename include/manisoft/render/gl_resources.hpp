// OpenGL resources of the renderer (gl_renderer.hpp): shader programs (compiled and linked, with
// the main program's uniform locations), meshes on the GPU (interleaved position + normal, 32-bit
// indices; dynamic ones re-use their buffers while they fit), the shadow map (a 24-bit depth
// texture with hardware comparison, read by percentage-closer filtering) and the render targets
// (colour RGBA8, object id R16UI, depth 24-bit renderbuffers; a second, single-sampled set to
// resolve MSAA into). Each needs the renderer's EGL context current.
#pragma once

#include <GL/glcorearb.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <ios>
#include <string>
#include <vector>

#include "manisoft/core/error.hpp"
#include "manisoft/render/scene.hpp"

namespace manisoft::render::detail_gl {

/// The info log of a shader or program (`get`: glGetShaderInfoLog or glGetProgramInfoLog).
inline std::string info_log(GLuint object, void (*get)(GLuint, GLsizei, GLsizei*, GLchar*)) {
  std::string log(4096, '\0');
  GLsizei length = 0;
  get(object, static_cast<GLsizei>(log.size()), &length, log.data());
  log.resize(static_cast<std::size_t>(length));
  return log;
}

/// A compiled shader; throws manisoft::Error with the compiler's log when it does not compile.
inline GLuint compile(GLenum type, const char* source) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    const std::string log = info_log(shader, glGetShaderInfoLog);
    glDeleteShader(shader);
    manisoft::detail::fail("GlRenderer: shader compilation failed: ", log);
  }
  return shader;
}

/// A linked program of a vertex and a fragment shader; throws manisoft::Error with the log.
inline GLuint link(const char* vertex, const std::string& fragment) {
  const GLuint vs = compile(GL_VERTEX_SHADER, vertex);
  GLuint fs = 0;
  try {
    fs = compile(GL_FRAGMENT_SHADER, fragment.c_str());
  } catch (...) {
    glDeleteShader(vs);
    throw;
  }
  const GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    const std::string log = info_log(program, glGetProgramInfoLog);
    glDeleteProgram(program);
    manisoft::detail::fail("GlRenderer: shader link failed: ", log);
  }
  return program;
}

/// A mesh on the GPU: interleaved position + normal, 32-bit indices.
struct GpuMesh {
  GLuint vao = 0, vbo = 0, ebo = 0;
  GLsizei index_count = 0;
  std::size_t vertex_capacity = 0, index_capacity = 0;
};

/// Uploads a mesh (`data`: scratch for the interleaved vertices). A dynamic mesh re-uses its
/// buffers while the mesh fits them.
inline void upload(GpuMesh& g, const Mesh& m, bool dynamic, std::vector<float>& data) {
  data.resize(m.positions.size() * 6);
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      data[6 * i + k] = m.positions[i][k];
      data[6 * i + 3 + k] = m.normals[i][k];
    }
  }
  if (g.vao == 0) {
    glGenVertexArrays(1, &g.vao);
    glGenBuffers(1, &g.vbo);
    glGenBuffers(1, &g.ebo);
    glBindVertexArray(g.vao);
    glBindBuffer(GL_ARRAY_BUFFER, g.vbo);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.ebo);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), reinterpret_cast<const void*>(3 * sizeof(float)));
  } else {
    glBindVertexArray(g.vao);
    glBindBuffer(GL_ARRAY_BUFFER, g.vbo);
  }
  const GLenum usage = dynamic ? GL_DYNAMIC_DRAW : GL_STATIC_DRAW;
  const auto vbytes = static_cast<GLsizeiptr>(data.size() * sizeof(float));
  const auto ibytes = static_cast<GLsizeiptr>(m.indices.size() * sizeof(std::uint32_t));
  if (m.positions.size() > g.vertex_capacity || !dynamic) {
    glBufferData(GL_ARRAY_BUFFER, vbytes, data.data(), usage);
    g.vertex_capacity = m.positions.size();
  } else {
    glBufferSubData(GL_ARRAY_BUFFER, 0, vbytes, data.data());
  }
  if (m.indices.size() > g.index_capacity || !dynamic) {
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, ibytes, m.indices.data(), usage);
    g.index_capacity = m.indices.size();
  } else {
    glBufferSubData(GL_ELEMENT_ARRAY_BUFFER, 0, ibytes, m.indices.data());
  }
  g.index_count = static_cast<GLsizei>(m.indices.size());
  glBindVertexArray(0);
}

inline void destroy(GpuMesh& g) {
  if (g.vao) glDeleteVertexArrays(1, &g.vao);
  if (g.vbo) glDeleteBuffers(1, &g.vbo);
  if (g.ebo) glDeleteBuffers(1, &g.ebo);
  g = GpuMesh{};
}

inline void draw(const GpuMesh& g) {
  if (g.index_count == 0) return;
  glBindVertexArray(g.vao);
  glDrawElements(GL_TRIANGLES, g.index_count, GL_UNSIGNED_INT, nullptr);
}

/// Uniform locations of a main program (gl_shaders.hpp); -1 where the specialisation has none.
struct Uniforms {
  GLint model, normal_matrix, view_projection, light_view_projection;
  GLint base_color, secondary_color, texture_scale, texture_strength, specular, shininess;
  GLint light_direction, light_position, spot_cos, light_color, ambient, camera_position;
  GLint shadow_map, shadow_window, shadow_size, shadow_bias, object_id;
};

inline Uniforms main_uniforms(GLuint program) {
  auto at = [program](const char* name) { return glGetUniformLocation(program, name); };
  return Uniforms{at("u_model"),           at("u_normal_matrix"),   at("u_view_projection"),  at("u_light_view_projection"),
                  at("u_base_color"),      at("u_secondary_color"), at("u_texture_scale"),    at("u_texture_strength"),
                  at("u_specular"),        at("u_shininess"),       at("u_light_direction"),  at("u_light_position"),
                  at("u_spot_cos"),        at("u_light_color"),     at("u_ambient"),          at("u_camera_position"),
                  at("u_shadow_map"),      at("u_shadow_window"),   at("u_shadow_size"),      at("u_shadow_bias"),
                  at("u_object_id")};
}

inline void check_framebuffer(const char* what) {
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) manisoft::detail::fail("GlRenderer: the ", what, " framebuffer is incomplete (status 0x", std::hex, status, ")");
}

/// The shadow map: a size x size depth texture compared with GL_LEQUAL (bilinear: GL_LINEAR),
/// attached to its own framebuffer.
struct ShadowMap {
  GLuint fbo = 0, texture = 0;

  void create(int size) {
    glGenTextures(1, &texture);
    glBindTexture(GL_TEXTURE_2D, texture);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, size, size, 0, GL_DEPTH_COMPONENT, GL_FLOAT, nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, texture, 0);
    glDrawBuffer(GL_NONE);
    glReadBuffer(GL_NONE);
    check_framebuffer("shadow map");
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
  }

  void destroy() {
    if (fbo) glDeleteFramebuffers(1, &fbo);
    if (texture) glDeleteTextures(1, &texture);
    fbo = texture = 0;
  }
};

/// Colour (RGBA8), id (R16UI) and depth (24-bit) renderbuffers of one size: multisampled ones
/// drawn into (main) and single-sampled ones they resolve into (only with MSAA).
struct RenderTargets {
  GLuint main_fbo = 0, resolve_fbo = 0;
  std::array<GLuint, 3> main_rbs{0, 0, 0}, resolve_rbs{0, 0, 0};
  int width = 0, height = 0;

  bool has_size(int w, int h) const { return w == width && h == height; }

  /// Replaces the targets by ones of width x height with `samples` (0: no multisampling).
  void create(int w, int h, int samples) {
    destroy();
    auto make_fbo = [&](GLuint& fbo, std::array<GLuint, 3>& rbs, int s) {
      glGenFramebuffers(1, &fbo);
      glBindFramebuffer(GL_FRAMEBUFFER, fbo);
      glGenRenderbuffers(3, rbs.data());
      const GLenum formats[3] = {GL_RGBA8, GL_R16UI, GL_DEPTH_COMPONENT24};
      const GLenum attachments[3] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_DEPTH_ATTACHMENT};
      for (int i = 0; i < 3; ++i) {
        glBindRenderbuffer(GL_RENDERBUFFER, rbs[static_cast<std::size_t>(i)]);
        glRenderbufferStorageMultisample(GL_RENDERBUFFER, s, formats[i], w, h);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, attachments[i], GL_RENDERBUFFER, rbs[static_cast<std::size_t>(i)]);
      }
      check_framebuffer(s > 0 ? "multisampled" : "main");
    };
    make_fbo(main_fbo, main_rbs, samples);
    if (samples > 0) make_fbo(resolve_fbo, resolve_rbs, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    width = w;
    height = h;
  }

  void destroy() {
    if (main_fbo) glDeleteFramebuffers(1, &main_fbo);
    if (resolve_fbo) glDeleteFramebuffers(1, &resolve_fbo);
    if (main_rbs[0]) glDeleteRenderbuffers(3, main_rbs.data());
    if (resolve_rbs[0]) glDeleteRenderbuffers(3, resolve_rbs.data());
    main_fbo = resolve_fbo = 0;
    main_rbs = {0, 0, 0};
    resolve_rbs = {0, 0, 0};
    width = height = 0;
  }
};

}  // namespace manisoft::render::detail_gl
