// The in-process OpenGL renderer (ManiSoft paper, section 3.2: the image V_t the
// policy sees each step): Blinn-Phong shading with one main light (directional or spot) and
// ambient light, a shadow map filtered with percentage-closer filtering (one bilinear comparison
// tap: the 2 x 2 texels around the point, weighted), procedural solid textures (wood, marble,
// fabric, checker, noise), optional MSAA, and per-frame read-back of colour, depth (depth buffer,
// linearised) and object ids (written as a second colour output of the same pass, MRT). Renders
// into framebuffer objects of an EGL context without a display (egl_context.hpp). Same inputs give
// the same pixels.
//
// Speed on a CPU (Mesa llvmpipe; measurements in BENCHMARKS.md): llvmpipe runs every instruction of a
// fragment shader on every pixel (both sides of a branch, under a mask), so the shaders are
// specialised at compile time (texture kind, light kind, shadows) and kept short; a directional
// light's shadow map is rendered only over the shadow casters' extent (a sub-rectangle of the map
// at the full map's texel size, so the shadows look the same as with the whole map); the shadow
// pass culls back faces; receivers that cast no shadow (the floor) run the shadow lookup only in
// the screen rectangle where the map's window can shadow them (the program without it elsewhere:
// the same pixels); opaque meshes are drawn small before large, receivers last (early depth test);
// the image is rendered upside down so that glReadPixels returns rows top first (no flipping
// copies), and colour is read as RGBA (llvmpipe's copy path); the id target is drawn only when the
// mask is read; glibc's heap trimming is relaxed (GlRendererOptions::keep_freed_heap). Between
// frames only what changed is redrawn (GlRendererOptions::incremental): rectangles around the
// moved instances, tube chunks and goal marker (before and after), the shadow map's texels their
// casters cover, and the pixels whose shadow lookup reads those texels (each drawable's box clipped
// to the prism those texels sweep along the light) are cleared, then each drawable that reaches
// them is drawn once under a scissor; the targets keep every other pixel, which a full redraw
// would draw identically (there a redrawn fragment fails the depth test).
#pragma once

#include <GL/glcorearb.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <vector>
#if defined(__GLIBC__)  // defined by the standard headers above
#include <malloc.h>     // mallopt (GlRendererOptions::keep_freed_heap)
#endif

#include "manisoft/core/error.hpp"
#include "manisoft/render/camera.hpp"
#include "manisoft/render/egl_context.hpp"
#include "manisoft/render/image.hpp"
#include "manisoft/render/mesh_builders.hpp"
#include "manisoft/render/scene.hpp"

namespace manisoft::render {

/// Fixed choices of a GlRenderer.
struct GlRendererOptions {
  bool shadows = true;
  /// Texels a side of the shadow map, in [64, 8192]. A directional light's map spans the shadow
  /// sphere (Lighting::shadow_center, shadow_radius); each frame only the part that the shadow
  /// casters cover (seen from the light) is rendered and cleared.
  int shadow_map_size = 1024;
  int msaa_samples = 0;        ///< 0 or 1: none; 2, 4, 8: multisampling
  bool read_depth = true;      ///< fill RenderOutput::depth
  bool read_mask = true;       ///< fill RenderOutput::mask
  /// glibc only: raise the process's heap trim threshold to 64 MiB (mallopt(M_TRIM_THRESHOLD),
  /// process-wide, once per GlRenderer). Mesa frees and re-allocates its large per-draw vertex
  /// buffers every frame; with glibc's default threshold the freed heap top is returned to the
  /// system and faulted back in each frame (several brk calls a frame, each a TLB shoot-down
  /// across CPUs; about 5% of a frame's CPU work on llvmpipe). The cost: up to 64 MiB of freed
  /// memory stays with the process.
  bool keep_freed_heap = true;
  /// Redraw only what changed since the previous frame of the same camera: screen rectangles
  /// around what moved (where it was and where it is) and, with a directional light, the part of
  /// the shadow map its shadow covers and the pixels that read that part. The targets keep the
  /// rest, so the image is the one a full redraw gives, pixel for pixel. Everything is drawn after
  /// set_scene(), a change of camera or of the shadow map's window, and with a spot light.
  bool incremental = true;
  EglOptions egl;
};

namespace detail_gl {

inline constexpr const char* main_vertex_shader = R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
uniform mat4 u_model;
uniform mat3 u_normal_matrix;
uniform mat4 u_view_projection;
uniform mat4 u_light_view_projection;
out vec3 v_world;
out vec3 v_normal;
out vec3 v_body;
out vec4 v_light_clip;
void main() {
  vec4 world = u_model * vec4(a_position, 1.0);
  v_world = world.xyz;
  v_normal = u_normal_matrix * a_normal;
  v_body = a_position;
  v_light_clip = u_light_view_projection * world;
  gl_Position = u_view_projection * world;
}
)";

// Specialised per texture kind and shadow switch (TEXTURE_KIND, SHADOWS are #defined before it):
// llvmpipe runs both sides of a branch under an execution mask, so a run-time switch would cost
// every pixel the noise of every texture.
inline constexpr const char* main_fragment_shader = R"(
in vec3 v_world;
in vec3 v_normal;
in vec3 v_body;
in vec4 v_light_clip;
uniform vec3 u_base_color;
uniform vec3 u_secondary_color;
uniform float u_texture_scale;
uniform float u_texture_strength;
uniform float u_specular;
uniform float u_shininess;
uniform vec3 u_light_direction;
uniform vec3 u_light_position;
uniform float u_spot_cos;
uniform vec3 u_light_color;
uniform vec3 u_ambient;
uniform vec3 u_camera_position;
uniform sampler2DShadow u_shadow_map;
uniform vec2 u_shadow_window;  // texels of the map that the light's projection covers (x, y)
uniform float u_shadow_size;   // texels a side of the whole map
uniform float u_shadow_bias;   // depth bias of one texel (normalised light depth)
uniform uint u_object_id;
layout(location = 0) out vec4 o_color;
layout(location = 1) out uint o_id;

// Value noise: trilinear (smoothstep-weighted) blend of a hash at the 8 corners of the unit cell.
// The hash of corner c is fract(q.x q.y q.z (q.x + q.y + q.z)) with q = 17 fract(c 0.3183099 +
// (0.1, 0.2, 0.3)); q's components depend on one axis each, so they are computed once per axis
// (low corner a, high corner b) and the products shared between corners.
float value_noise(vec3 x) {
  vec3 i = floor(x);
  vec3 f = fract(x);
  f = f * f * (3.0 - 2.0 * f);
  vec3 a = fract(i * 0.3183099 + vec3(0.1, 0.2, 0.3)) * 17.0;
  vec3 b = fract((i + 1.0) * 0.3183099 + vec3(0.1, 0.2, 0.3)) * 17.0;
  vec4 xy = vec4(a.x * a.y, b.x * a.y, a.x * b.y, b.x * b.y);  // corners (0,0) (1,0) (0,1) (1,1) in x, y
  vec4 sxy = vec4(a.x + a.y, b.x + a.y, a.x + b.y, b.x + b.y);
  vec4 h0 = fract(xy * a.z * (sxy + a.z));  // z = 0
  vec4 h1 = fract(xy * b.z * (sxy + b.z));  // z = 1
  vec4 h = mix(h0, h1, f.z);
  vec2 hy = mix(h.xz, h.yw, f.x);
  return mix(hy.x, hy.y, f.y);
}
float fbm(vec3 p) {
  float sum = 0.0, amplitude = 0.5;
  for (int i = 0; i < 4; ++i) { sum += amplitude * value_noise(p); p = p * 2.03 + vec3(1.7, 9.2, 5.1); amplitude *= 0.5; }
  return sum / 0.9375;
}
// Pattern weight in [0, 1]: 0 = base colour, 1 = secondary colour.
float pattern(vec3 p) {
  float s = u_texture_scale;
#if TEXTURE_KIND == 1
  {  // wood: growth rings about the body x axis, grain along x, noisy
    float r = length(p.yz) * s + 1.2 * fbm(p * vec3(0.8, 6.0, 6.0) * s * 0.25);
    float ring = fract(r);
    return smoothstep(0.0, 0.25, ring) * smoothstep(1.0, 0.55, ring) * 0.8 + 0.2 * fbm(p * vec3(2.0, 40.0, 40.0));
  }
#elif TEXTURE_KIND == 2
  {  // marble: turbulent sine veins
    float v = sin((p.x + 0.6 * p.y + 0.3 * p.z) * s + 6.0 * fbm(p * s * 0.5));
    return pow(1.0 - abs(v), 6.0);
  }
#elif TEXTURE_KIND == 3
  {  // fabric: over-under weave of two thread sets
    vec3 q = p * s;
    float warp = 0.5 + 0.5 * sin(q.x * 6.2831853);
    float weft = 0.5 + 0.5 * sin((q.y + q.z) * 6.2831853);
    float cell = mod(floor(q.x) + floor(q.y + q.z), 2.0);
    return mix(warp, weft, cell) * 0.8 + 0.2 * value_noise(q * 8.0);
  }
#elif TEXTURE_KIND == 4
  {  // checker
    vec3 q = floor(p * s + vec3(1e-3));
    return mod(q.x + q.y + q.z, 2.0);
  }
#elif TEXTURE_KIND == 5
  {  // noise
    return fbm(p * s);
  }
#endif
  return 0.0;
}
// Fraction of the light reaching the point: one percentage-closer tap over the 2 x 2 texels
// around it, bilinearly weighted (what a GL_LINEAR comparison sampler returns; textureGather of
// the four comparisons is cheaper on llvmpipe). p.xy in [0, 1] spans u_shadow_window texels.
float shadow_factor(float ndl) {
#if LIGHT_KIND == 0
  vec3 p = v_light_clip.xyz * 0.5 + 0.5;  // orthographic: w = 1
#else
  vec3 p = v_light_clip.xyz / v_light_clip.w * 0.5 + 0.5;
#endif
  if (p.z >= 1.0 || p.x <= 0.0 || p.y <= 0.0 || p.x >= 1.0 || p.y >= 1.0) return 1.0;
  float z = p.z - u_shadow_bias * (0.5 + 1.5 * (1.0 - ndl));
  vec2 t = p.xy * u_shadow_window;
#if GATHER
  t -= 0.5;
  vec2 f = fract(t);
  vec4 g = textureGather(u_shadow_map, (floor(t) + 1.0) / u_shadow_size, z);  // (i,j+1) (i+1,j+1) (i+1,j) (i,j)
  return mix(mix(g.w, g.z, f.x), mix(g.x, g.y, f.x), f.y);
#else
  return texture(u_shadow_map, vec3(t / u_shadow_size, z));
#endif
}
// x^(1/2.2) for x in [0, 1] from square roots (llvmpipe's pow is a long polynomial): a fit in
// x^(1/4), x^(1/2), x^(3/4), x within 0.11 of an 8-bit level.
vec3 gamma_encode(vec3 x) {
  vec3 q = sqrt(sqrt(x));
  return q * (0.033443686 + q * (1.24112311 - 0.415407581 * q)) + 0.141269234 * x;
}
void main() {
  vec3 n = normalize(v_normal);  // back faces are culled: n faces the camera's side
  vec3 albedo = u_base_color;
#if TEXTURE_KIND != 0
  albedo = mix(u_base_color, u_secondary_color, clamp(pattern(v_body) * u_texture_strength, 0.0, 1.0));
#endif
#if LIGHT_KIND == 0
  vec3 l = -u_light_direction;
  float lit = 1.0;
#else
  vec3 d = normalize(v_world - u_light_position);
  vec3 l = -d;
  float lit = smoothstep(u_spot_cos, u_spot_cos + 0.03, dot(d, u_light_direction));
#endif
  float ndl = max(dot(n, l), 0.0);
#if SHADOWS
  if (ndl > 0.0 && lit > 0.0) lit *= shadow_factor(ndl);
#endif
  vec3 v = normalize(u_camera_position - v_world);
  vec3 h = normalize(l + v);
  float specular = ndl > 0.0 ? u_specular * pow(max(dot(n, h), 0.0), u_shininess) : 0.0;
  vec3 ambient = u_ambient * (0.8 + 0.2 * n.z);
  vec3 color = albedo * ambient + (albedo * ndl + vec3(specular)) * u_light_color * lit;
  o_color = vec4(gamma_encode(clamp(color, 0.0, 1.0)), 1.0);
  o_id = u_object_id;
}
)";

inline constexpr const char* shadow_vertex_shader = R"(#version 330 core
layout(location = 0) in vec3 a_position;
uniform mat4 u_model;
uniform mat4 u_light_view_projection;
void main() { gl_Position = u_light_view_projection * (u_model * vec4(a_position, 1.0)); }
)";

inline constexpr const char* shadow_fragment_shader = R"(#version 330 core
void main() {}
)";

inline GLuint compile(GLenum type, const char* source) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    std::string log(4096, '\0');
    GLsizei length = 0;
    glGetShaderInfoLog(shader, static_cast<GLsizei>(log.size()), &length, log.data());
    log.resize(static_cast<std::size_t>(length));
    glDeleteShader(shader);
    manisoft::detail::fail("GlRenderer: shader compilation failed: ", log);
  }
  return shader;
}

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
    std::string log(4096, '\0');
    GLsizei length = 0;
    glGetProgramInfoLog(program, static_cast<GLsizei>(log.size()), &length, log.data());
    log.resize(static_cast<std::size_t>(length));
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

inline Eigen::Matrix4f look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, const Eigen::Vector3d& up_hint) {
  const Eigen::Vector3d f = (target - eye).normalized();
  Eigen::Vector3d up = up_hint;
  if (std::abs(f.dot(up.normalized())) > 0.99) up = Eigen::Vector3d::UnitY();
  const Eigen::Vector3d s = f.cross(up).normalized();
  const Eigen::Vector3d u = s.cross(f);
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.row(0).head<3>() = s.transpose();
  m.row(1).head<3>() = u.transpose();
  m.row(2).head<3>() = -f.transpose();
  m(0, 3) = -s.dot(eye);
  m(1, 3) = -u.dot(eye);
  m(2, 3) = f.dot(eye);
  return m.cast<float>();
}

inline Eigen::Matrix4d perspective(double fov_y_rad, double aspect, double near_clip, double far_clip) {
  const double f = 1.0 / std::tan(0.5 * fov_y_rad);
  Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
  p(0, 0) = f / aspect;
  p(1, 1) = f;
  p(2, 2) = (far_clip + near_clip) / (near_clip - far_clip);
  p(2, 3) = 2 * far_clip * near_clip / (near_clip - far_clip);
  p(3, 2) = -1;
  return p;
}

inline Eigen::Matrix4d orthographic(double half_width, double near_clip, double far_clip) {
  Eigen::Matrix4d p = Eigen::Matrix4d::Identity();
  p(0, 0) = 1.0 / half_width;
  p(1, 1) = 1.0 / half_width;
  p(2, 2) = -2.0 / (far_clip - near_clip);
  p(2, 3) = -(far_clip + near_clip) / (far_clip - near_clip);
  return p;
}

}  // namespace detail_gl

/// OpenGL renderer: set_scene() once, render() per frame. Not copyable; uses its EGL context on
/// the calling thread. Construction throws manisoft::Error when no EGL display or context can be
/// had, or for invalid options.
class GlRenderer {
 public:
  explicit GlRenderer(const GlRendererOptions& options = {}) : options_(options) {
    if (options_.shadow_map_size < 64 || options_.shadow_map_size > 8192) {
      manisoft::detail::fail("GlRenderer shadow_map_size = ", options_.shadow_map_size, " is invalid: it must lie in [64, 8192]");
    }
    if (!(options_.msaa_samples == 0 || options_.msaa_samples == 1 || options_.msaa_samples == 2 || options_.msaa_samples == 4 ||
          options_.msaa_samples == 8)) {
      manisoft::detail::fail("GlRenderer msaa_samples = ", options_.msaa_samples, " is invalid: 0, 1, 2, 4 or 8");
    }
#if defined(__GLIBC__)
    if (options_.keep_freed_heap) mallopt(M_TRIM_THRESHOLD, 64 << 20);
#endif
    context_ = std::make_unique<EglContext>(options_.egl);
    try {
      GLint major = 0;
      glGetIntegerv(GL_MAJOR_VERSION, &major);
      gather_ = major >= 4;  // textureGather on shadow samplers: GLSL 4.00
      build_programs(0);     // directional light; a spot light's set is built by set_scene
      shadow_program_ = detail_gl::link(detail_gl::shadow_vertex_shader, detail_gl::shadow_fragment_shader);
      u_shadow_model_ = glGetUniformLocation(shadow_program_, "u_model");
      u_shadow_light_vp_ = glGetUniformLocation(shadow_program_, "u_light_view_projection");
      if (options_.shadows) create_shadow_map();
    } catch (...) {
      release();
      throw;
    }
  }

  GlRenderer(const GlRenderer&) = delete;
  GlRenderer& operator=(const GlRenderer&) = delete;
  ~GlRenderer() { release(); }

  const GlRendererOptions& options() const { return options_; }

  /// The OpenGL renderer and version strings (e.g. "llvmpipe (LLVM 15.0.6, 256 bits)").
  std::string device_name() const {
    context_->make_current();
    const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    const auto* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
    return std::string(renderer ? renderer : "?") + ", OpenGL " + (version ? version : "?");
  }

  /// Uploads the scene's meshes; checks indices, ids and cameras. Replaces any previous scene.
  void set_scene(const SceneDescription& scene) {
    context_->make_current();
    validate_scene(scene);
    drawn_.valid = false;  // the targets no longer hold a frame of the scene being set
    const std::size_t light_set = scene.lighting.kind == LightKind::spot ? 1 : 0;
    build_programs(light_set);
    // Receivers (instances that cast no shadow, e.g. the floor) are drawn without the shadow
    // lookup where they cannot be in shadow (render_into): their programs without shadows.
    if (options_.shadows) {
      for (const Instance& inst : scene.instances) {
        const auto kind = static_cast<std::size_t>(scene.materials[static_cast<std::size_t>(inst.material)].texture);
        if (!inst.casts_shadow) ensure_program(light_set, 0, kind);
      }
    }
    mesh_bounds_.clear();
    for (const Mesh& m : scene.meshes) {
      Eigen::AlignedBox3f box;
      for (const Eigen::Vector3f& p : m.positions) box.extend(p);
      mesh_bounds_.push_back(box);
    }
    for (auto& g : meshes_) detail_gl::destroy(g);
    meshes_.assign(scene.meshes.size(), detail_gl::GpuMesh{});
    for (std::size_t i = 0; i < scene.meshes.size(); ++i) detail_gl::upload(meshes_[i], scene.meshes[i], false, upload_scratch_);
    for (auto& g : triad_) detail_gl::destroy(g);
    const std::vector<Mesh> triad = make_axis_triad(scene.goal_marker.axis_length, scene.goal_marker.axis_width);
    triad_bounds_.setEmpty();
    for (std::size_t i = 0; i < 3; ++i) {
      detail_gl::upload(triad_[i], triad[i], false, upload_scratch_);
      for (const Eigen::Vector3f& p : triad[i].positions) triad_bounds_.extend(p);
    }
    // Draw order: shadow casters before receivers (the floor), each by increasing mesh bounding
    // box volume, so that small objects are drawn before the table they stand on.
    draw_order_.resize(scene.instances.size());
    for (std::size_t i = 0; i < draw_order_.size(); ++i) draw_order_[i] = i;
    auto volume = [&](std::size_t i) {
      const Eigen::AlignedBox3f& box = mesh_bounds_[static_cast<std::size_t>(scene.instances[i].mesh)];
      return box.isEmpty() ? 0.0f : box.volume();
    };
    std::stable_sort(draw_order_.begin(), draw_order_.end(), [&](std::size_t a, std::size_t b) {
      const bool ca = scene.instances[a].casts_shadow, cb = scene.instances[b].casts_shadow;
      return ca != cb ? ca : volume(a) < volume(b);
    });
    scene_ = scene;
    have_scene_ = true;
  }

  const SceneDescription& scene() const { return scene_; }

  /// What the last render() drew (GlRendererOptions::incremental).
  struct DrawStats {
    bool everything = true;          ///< the whole image and shadow window
    std::size_t rectangles = 0;      ///< screen rectangles cleared and redrawn
    std::size_t pixels = 0;          ///< pixels in them (overlaps counted twice)
    std::size_t shadow_texels = 0;   ///< shadow-map texels cleared and redrawn
  };
  const DrawStats& last_draw() const { return stats_; }

  /// Renders one frame seen by scene().cameras[camera_index].
  RenderOutput render(const FrameState& frame, std::size_t camera_index = 0) {
    RenderOutput out;
    render_into(frame, out, camera_index);
    return out;
  }

  /// As render(), reusing `out`'s buffers (no allocation once they have the right size).
  void render_into(const FrameState& frame, RenderOutput& out, std::size_t camera_index = 0) {
    if (!have_scene_) manisoft::detail::fail("GlRenderer::render: call set_scene() first");
    if (camera_index >= scene_.cameras.size()) {
      manisoft::detail::fail("GlRenderer::render: camera_index = ", camera_index, " is out of range: the scene has ", scene_.cameras.size(),
                             " camera(s)");
    }
    if (frame.instance_poses.size() != scene_.instances.size()) {
      manisoft::detail::fail("GlRenderer::render: ", frame.instance_poses.size(), " instance poses for ", scene_.instances.size(),
                             " instances: need one pose per instance");
    }
    for (std::size_t i = 0; i < frame.instance_poses.size(); ++i) {
      if (!frame.instance_poses[i].is_finite()) manisoft::detail::fail("GlRenderer::render: pose of instance ", i, " (", scene_.instances[i].name, ") is not finite");
    }
    if (frame.goal_pose && !frame.goal_pose->is_finite()) manisoft::detail::fail("GlRenderer::render: the goal pose is not finite");
    const Camera& camera = scene_.cameras[camera_index];
    const CameraModel model = camera_model(camera);
    context_->make_current();
    ensure_targets(camera.width, camera.height);
    const int w = camera.width, h = camera.height;
    const PixelRect whole{0, 0, w, h};

    // The targets hold this camera's previous frame (incremental drawing) until drawing starts.
    const bool keep = options_.incremental && drawn_.valid && drawn_.camera == camera_index;
    drawn_.valid = false;
    const bool draw_rod = scene_.rod.present && frame.rod.nodes.rows() >= 2;
    const bool rod_changed = !keep || draw_rod != drawn_.rod || (draw_rod && !drawn_.same_rod(frame.rod));
    if (draw_rod && rod_changed) {
      TubeOptions tube;
      tube.sides = scene_.rod.sides;
      tube.subdivisions = scene_.rod.subdivisions;
      make_tube_into(rod_mesh_, frame.rod.nodes, frame.rod.directors, frame.rod.radius, tube);
      detail_gl::upload(rod_gpu_, rod_mesh_, true, upload_scratch_);
    }

    const ShadowProjection shadow = options_.shadows ? shadow_projection(frame, draw_rod) : ShadowProjection{};
    // OpenCV camera (y down, z forward) -> GL eye (y up, z back), then the image turned upside
    // down (clip y negated) so that GL's bottom-up rows come back top row first: the mirror turns
    // counter-clockwise front faces clockwise.
    Eigen::Matrix4d cv_to_gl = Eigen::Matrix4d::Identity();
    cv_to_gl(1, 1) = -1;
    cv_to_gl(2, 2) = -1;
    Eigen::Matrix4d flip_rows = Eigen::Matrix4d::Identity();
    flip_rows(1, 1) = -1;
    Eigen::Matrix4d world_to_camera = Eigen::Matrix4d::Identity();
    world_to_camera.topLeftCorner<3, 3>() = model.R;
    world_to_camera.topRightCorner<3, 1>() = model.t;
    const Eigen::Matrix4f view_projection =
        (flip_rows *
         detail_gl::perspective(camera.fov_y_deg * std::numbers::pi / 180.0, static_cast<double>(camera.width) / camera.height, camera.near_clip,
                                camera.far_clip) *
         cv_to_gl * world_to_camera)
            .cast<float>();

    // What to draw: the whole image, or (incremental) the rectangles around what changed; the
    // shadow map's window, or its texels that changed casters cover (before and after).
    const bool incremental = keep && (!options_.shadows || (shadow.windowed && shadow.view_projection == drawn_.shadow_view_projection));
    dirty_.clear();
    light_dirty_.clear();
    if (incremental) {
      collect_changes(frame, draw_rod, rod_changed, shadow, view_projection, w, h);
    } else {
      dirty_.push_back(whole);
      // The window and one texel beyond it: a bilinear tap at its edge reads it.
      if (options_.shadows) light_dirty_.push_back(PixelRect{0, 0, shadow.limit_x(options_.shadow_map_size), shadow.limit_y(options_.shadow_map_size)});
      if (draw_rod) {
        rod_chunk_boxes(drawn_.rod_chunks);
      } else {
        drawn_.rod_chunks.clear();
      }
    }

    merge_rects(dirty_, max_dirty_rects);
    stats_ = DrawStats{!incremental, dirty_.size(), 0, 0};
    for (const PixelRect& r : dirty_) stats_.pixels += static_cast<std::size_t>(area(r));
    for (const PixelRect& r : light_dirty_) stats_.shadow_texels += static_cast<std::size_t>(area(r));

    if (!light_dirty_.empty()) draw_shadow_pass(frame, draw_rod, incremental, shadow);
    if (!dirty_.empty()) draw_main_pass(frame, camera, draw_rod, incremental, shadow, view_projection);

    // Resolve MSAA, then read back. Rows come back top row first (the image was drawn upside down).
    GLuint read_fbo = main_fbo_;
    if (options_.msaa_samples > 1) {
      glBindFramebuffer(GL_READ_FRAMEBUFFER, main_fbo_);
      glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_fbo_);
      for (int a = 0; a < (options_.read_mask ? 2 : 1); ++a) {
        glReadBuffer(GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(a));
        const GLenum draw_buffers[2] = {a == 0 ? GLenum(GL_COLOR_ATTACHMENT0) : GLenum(GL_NONE), a == 1 ? GLenum(GL_COLOR_ATTACHMENT1) : GLenum(GL_NONE)};
        glDrawBuffers(2, draw_buffers);
        glBlitFramebuffer(0, 0, camera.width, camera.height, 0, 0, camera.width, camera.height,
                          GL_COLOR_BUFFER_BIT | (a == 0 && options_.read_depth ? GL_DEPTH_BUFFER_BIT : 0), GL_NEAREST);
      }
      read_fbo = resolve_fbo_;
    }
    glFrontFace(GL_CCW);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, read_fbo);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    const std::size_t pixels = static_cast<std::size_t>(w) * h;
    out.width = w;
    out.height = h;
    out.camera = model;
    // RGBA is llvmpipe's copy path (RGBA8 target); GL_RGB goes through Mesa's format conversion
    // (about 8x slower): read RGBA and drop alpha here.
    out.rgb.resize(pixels * 3);
    scratch_rgba_.resize(pixels);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, scratch_rgba_.data());
    const std::array<std::uint8_t, 4>* rgba = scratch_rgba_.data();
    std::uint8_t* rgb = out.rgb.data();
    for (std::size_t i = 0; i < pixels; ++i) {
      rgb[3 * i] = rgba[i][0];
      rgb[3 * i + 1] = rgba[i][1];
      rgb[3 * i + 2] = rgba[i][2];
    }
    if (options_.read_mask) {
      out.mask.resize(pixels);
      glReadBuffer(GL_COLOR_ATTACHMENT1);
      glReadPixels(0, 0, w, h, GL_RED_INTEGER, GL_UNSIGNED_SHORT, out.mask.data());
    } else {
      out.mask.clear();
    }
    if (options_.read_depth) {
      scratch_depth_.resize(pixels);
      out.depth.resize(pixels);
      glReadPixels(0, 0, w, h, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, scratch_depth_.data());
      // The 24-bit depth D = u >> 8, window depth d = D / M (M = 2^24 - 1) -> NDC z = 2 d - 1 -> eye
      // distance 2 n f / ((f + n) - z (f - n)) = n f / (n + (1 - d) (f - n)); 1 - d from integers
      // (no cancellation), in float (vectorised).
      const float n = static_cast<float>(camera.near_clip), f = static_cast<float>(camera.far_clip);
      const float nf = n * f, scale = static_cast<float>((camera.far_clip - camera.near_clip) / 16777215.0);
      const std::uint32_t* src = scratch_depth_.data();
      float* dst = out.depth.data();
      for (std::size_t i = 0; i < pixels; ++i) {
        const auto far_steps = static_cast<std::int32_t>(0xFFFFFFu - (src[i] >> 8));  // M - D
        const float z = nf / (n + static_cast<float>(far_steps) * scale);
        dst[i] = far_steps == 0 ? 0.0f : z;
      }
    } else {
      out.depth.clear();
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    const GLenum error = glGetError();
    if (error != GL_NO_ERROR) manisoft::detail::fail("GlRenderer::render: OpenGL error 0x", std::hex, error);
    if (options_.incremental) drawn_.record(frame, draw_rod, rod_mesh_, camera_index, shadow.view_projection);
  }

 private:
  struct Uniforms {
    GLint model, normal_matrix, view_projection, light_view_projection;
    GLint base_color, secondary_color, texture_scale, texture_strength, specular, shininess;
    GLint light_direction, light_position, spot_cos, light_color, ambient, camera_position;
    GLint shadow_map, shadow_window, shadow_size, shadow_bias, object_id;
  };

  // Compiles the main programs of one light kind (0 directional, 1 spot), one per texture kind,
  // with shadows when the options ask for them.
  void build_programs(std::size_t light_set) {
    for (std::size_t kind = 0; kind < texture_kinds; ++kind) ensure_program(light_set, options_.shadows ? 1 : 0, kind);
  }

  // Compiles one main program variant unless it exists.
  void ensure_program(std::size_t light_set, std::size_t shadowed, std::size_t kind) {
    if (programs_[light_set][shadowed][kind] != 0) return;
    const std::string source = std::string(gather_ ? "#version 400 core\n" : "#version 330 core\n") + "#define TEXTURE_KIND " +
                               std::to_string(kind) + "\n#define SHADOWS " + std::to_string(shadowed) + "\n#define LIGHT_KIND " +
                               std::to_string(light_set) + "\n#define GATHER " + (gather_ ? "1" : "0") + "\n" + detail_gl::main_fragment_shader;
    const GLuint program = detail_gl::link(detail_gl::main_vertex_shader, source);
    programs_[light_set][shadowed][kind] = program;
    auto at = [program](const char* name) { return glGetUniformLocation(program, name); };
    uniforms_[light_set][shadowed][kind] = Uniforms{at("u_model"),           at("u_normal_matrix"),   at("u_view_projection"),  at("u_light_view_projection"),
                                                    at("u_base_color"),      at("u_secondary_color"), at("u_texture_scale"),    at("u_texture_strength"),
                                                    at("u_specular"),        at("u_shininess"),       at("u_light_direction"),  at("u_light_position"),
                                                    at("u_spot_cos"),        at("u_light_color"),     at("u_ambient"),          at("u_camera_position"),
                                                    at("u_shadow_map"),      at("u_shadow_window"),   at("u_shadow_size"),      at("u_shadow_bias"),
                                                    at("u_object_id")};
  }

  void validate_scene(const SceneDescription& scene) const {
    if (scene.cameras.empty()) manisoft::detail::fail("SceneDescription: no camera: at least one is needed");
    for (const Camera& c : scene.cameras) validate(c);
    if (scene.materials.empty()) manisoft::detail::fail("SceneDescription: no material: at least one is needed");
    for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
      const Mesh& m = scene.meshes[i];
      if (m.normals.size() != m.positions.size()) {
        manisoft::detail::fail("SceneDescription mesh ", i, ": ", m.normals.size(), " normals for ", m.positions.size(), " positions");
      }
      if (m.indices.size() % 3 != 0) manisoft::detail::fail("SceneDescription mesh ", i, ": ", m.indices.size(), " indices is not a multiple of 3");
      for (std::uint32_t idx : m.indices) {
        if (idx >= m.positions.size()) manisoft::detail::fail("SceneDescription mesh ", i, ": index ", idx, " >= vertex count ", m.positions.size());
      }
    }
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
      const Instance& inst = scene.instances[i];
      if (inst.mesh < 0 || static_cast<std::size_t>(inst.mesh) >= scene.meshes.size()) {
        manisoft::detail::fail("SceneDescription instance ", i, " (", inst.name, "): mesh = ", inst.mesh, " out of range [0, ", scene.meshes.size(), ")");
      }
      if (inst.material < 0 || static_cast<std::size_t>(inst.material) >= scene.materials.size()) {
        manisoft::detail::fail("SceneDescription instance ", i, " (", inst.name, "): material = ", inst.material, " out of range [0, ",
                               scene.materials.size(), ")");
      }
      if (inst.object_id == 0) manisoft::detail::fail("SceneDescription instance ", i, " (", inst.name, "): object_id 0 is reserved for the background");
    }
    if (scene.rod.present && (scene.rod.material < 0 || static_cast<std::size_t>(scene.rod.material) >= scene.materials.size())) {
      manisoft::detail::fail("SceneDescription rod: material = ", scene.rod.material, " out of range [0, ", scene.materials.size(), ")");
    }
    const Lighting& l = scene.lighting;
    if (!(l.direction.norm() > 0) || !l.direction.allFinite()) manisoft::detail::fail("Lighting direction must be finite and non-zero");
    if (l.kind == LightKind::spot && !(l.spot_cone_deg > 0 && l.spot_cone_deg <= 80)) {
      manisoft::detail::fail("Lighting spot_cone_deg = ", l.spot_cone_deg, " is invalid: it must lie in (0, 80]");
    }
    manisoft::detail::require_positive("Lighting shadow_radius", l.shadow_radius);
    manisoft::detail::require_non_negative("Lighting intensity", l.intensity);
    manisoft::detail::require_non_negative("Lighting ambient_intensity", l.ambient_intensity);
  }

  /// The light's view-projection and the part of the shadow map it covers.
  struct ShadowProjection {
    Eigen::Matrix4f view_projection = Eigen::Matrix4f::Identity();
    int window_x = 1, window_y = 1;  ///< texels
    float bias = 0;                  ///< normalised light depth of one texel
    /// Directional light: the light's view and the window's extent in it (x, y, metres); only
    /// points inside it can be in shadow.
    bool windowed = false;
    Eigen::Matrix4f view = Eigen::Matrix4f::Identity();
    Eigen::Vector2f window_min = Eigen::Vector2f::Zero(), window_max = Eigen::Vector2f::Zero();
    // The texels the pass may clear: the window and one beyond (a bilinear tap at its edge).
    int limit_x(int map_size) const { return std::min(window_x + 1, map_size); }
    int limit_y(int map_size) const { return std::min(window_y + 1, map_size); }
  };

  /// A rectangle of framebuffer pixels [x0, x1) x [y0, y1).
  struct PixelRect {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    bool empty() const { return x1 <= x0 || y1 <= y0; }
  };

  /// The image minus `inside`: up to four rectangles (bands below and above, then left and right).
  static std::array<PixelRect, 4> complement(const PixelRect& inside, int width, int height) {
    if (inside.empty()) return {PixelRect{0, 0, width, height}, PixelRect{}, PixelRect{}, PixelRect{}};
    return {PixelRect{0, 0, width, inside.y0}, PixelRect{0, inside.y1, width, height}, PixelRect{0, inside.y0, inside.x0, inside.y1},
            PixelRect{inside.x1, inside.y0, width, inside.y1}};
  }

  // The pixels where a receiver can be in shadow: its world bounding box clipped to the prism
  // that the shadow map's window sweeps along the light (light-view x, y inside the window, one
  // texel added). The whole image when that cannot be bounded (spot light).
  static PixelRect shadowed_screen_rect(const math::Pose<double>& pose, const Eigen::AlignedBox3f& body_box, const ShadowProjection& shadow,
                                        const Eigen::Matrix4f& view_projection, int width, int height) {
    if (!shadow.windowed || body_box.isEmpty()) return PixelRect{0, 0, width, height};
    const Eigen::Vector2f margin = Eigen::Vector2f::Constant((shadow.window_max.x() - shadow.window_min.x()) / static_cast<float>(shadow.window_x));
    return prism_screen_rect(world_box(pose, body_box), shadow.view, shadow.window_min - margin, shadow.window_max + margin, view_projection, width,
                             height);
  }

  // The pixels of a world box's part inside the prism {light-view x, y in [lo, hi]} (`light_view`:
  // world to the light's view), projected into the image, plus one pixel: the box clipped face by
  // face. The whole image when part of the clipped box is behind the camera; empty when the box
  // misses the prism.
  static PixelRect prism_screen_rect(const Eigen::AlignedBox3f& box, const Eigen::Matrix4f& light_view, const Eigen::Vector2f& lo,
                                     const Eigen::Vector2f& hi, const Eigen::Matrix4f& view_projection, int width, int height) {
    const PixelRect whole{0, 0, width, height};
    if (box.isEmpty()) return PixelRect{};
    // The box's faces as corner indices (bit 0: x max, bit 1: y max, bit 2: z max).
    static constexpr std::array<std::array<int, 4>, 6> faces = {{{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}}};
    Eigen::AlignedBox2f pixels;
    for (const auto& face : faces) {
      // Sutherland-Hodgman against the prism's four planes: each adds at most one vertex.
      std::array<Eigen::Vector3f, 8> polygon, clipped;
      int n = 4;
      for (int k = 0; k < 4; ++k) polygon[static_cast<std::size_t>(k)] = box.corner(static_cast<Eigen::AlignedBox3f::CornerType>(face[static_cast<std::size_t>(k)]));
      for (int plane = 0; plane < 4 && n > 0; ++plane) {
        const int axis = plane / 2;
        const float sign = plane % 2 == 0 ? 1.0f : -1.0f;  // inside: sign (light-view coordinate - bound) >= 0
        const float bound = plane % 2 == 0 ? lo[axis] : hi[axis];
        auto distance = [&](const Eigen::Vector3f& p) { return sign * (light_view.row(axis).head<3>().dot(p) + light_view(axis, 3) - bound); };
        int m = 0;
        for (int k = 0; k < n; ++k) {
          const Eigen::Vector3f& a = polygon[static_cast<std::size_t>(k)];
          const Eigen::Vector3f& b = polygon[static_cast<std::size_t>((k + 1) % n)];
          const float da = distance(a), db = distance(b);
          if (da >= 0) clipped[static_cast<std::size_t>(m++)] = a;
          if ((da >= 0) != (db >= 0)) clipped[static_cast<std::size_t>(m++)] = a + (b - a) * (da / (da - db));
        }
        polygon = clipped;
        n = m;
      }
      for (int k = 0; k < n; ++k) {
        const Eigen::Vector4f clip = view_projection * polygon[static_cast<std::size_t>(k)].homogeneous();
        if (!(clip.w() > 1e-6f)) return whole;
        pixels.extend(clip_to_pixels(clip, width, height));
      }
    }
    return to_pixels(pixels, 1.0f, width, height);
  }

  // A spot light: a perspective frustum over its cone, the whole map. A directional light: an
  // orthographic projection whose texels are those of the whole map spanning the shadow sphere
  // (side 2 r), restricted to the texels that the shadow casters cover as seen from the light
  // (plus one texel a side): the shadow map's contents there are those of the whole map, at a
  // fraction of the fill and clear cost.
  ShadowProjection shadow_projection(const FrameState& frame, bool draw_rod) const {
    const Lighting& l = scene_.lighting;
    const Eigen::Vector3d dir = l.direction.normalized();
    const int size = options_.shadow_map_size;
    ShadowProjection out;
    out.bias = 1.0f / static_cast<float>(size);
    if (l.kind != LightKind::directional) {
      out.view_projection = detail_gl::perspective(2.0 * l.spot_cone_deg * std::numbers::pi / 180.0, 1.0, 0.1, 20.0).cast<float>() *
                            detail_gl::look_at(l.position, l.position + dir, Eigen::Vector3d::UnitZ());
      out.window_x = out.window_y = size;
      return out;
    }
    const double r = l.shadow_radius;
    const Eigen::Vector3d eye = l.shadow_center - dir * (2.0 * r);
    const Eigen::Matrix4f view = detail_gl::look_at(eye, l.shadow_center, Eigen::Vector3d::UnitZ());
    // The casters' extent in the light's view (x, y).
    Eigen::AlignedBox2f extent;
    for (std::size_t i = 0; i < scene_.instances.size(); ++i) {
      const Instance& inst = scene_.instances[i];
      if (!inst.casts_shadow) continue;
      const Eigen::AlignedBox3f& box = mesh_bounds_[static_cast<std::size_t>(inst.mesh)];
      if (box.isEmpty()) continue;
      const Eigen::Matrix4f to_light = view * frame.instance_poses[i].matrix().cast<float>();
      for (int c = 0; c < 8; ++c) {
        const Eigen::Vector3f corner = box.corner(static_cast<Eigen::AlignedBox3f::CornerType>(c));
        extent.extend((to_light.topLeftCorner<2, 3>() * corner + to_light.topRightCorner<2, 1>()).eval());
      }
    }
    if (draw_rod) {
      for (const Eigen::Vector3f& p : rod_mesh_.positions) extent.extend((view.topLeftCorner<2, 3>() * p + view.topRightCorner<2, 1>()).eval());
    }
    // Whole-map texel k spans [-r + k tau, -r + (k + 1) tau]; the window is texels [k0, k1).
    const double tau = 2.0 * r / size;
    std::array<int, 2> k0{0, 0}, k1{1, 1};
    if (!extent.isEmpty()) {
      for (int a = 0; a < 2; ++a) {
        k0[a] = std::clamp(static_cast<int>(std::floor((extent.min()[a] + r) / tau)) - 1, 0, size - 1);
        k1[a] = std::clamp(static_cast<int>(std::ceil((extent.max()[a] + r) / tau)) + 1, k0[a] + 1, size);
      }
    }
    Eigen::Matrix4d projection = detail_gl::orthographic(r, 0.5 * r, 3.5 * r);
    for (int a = 0; a < 2; ++a) {
      const double lo = -r + k0[a] * tau, hi = -r + k1[a] * tau;
      projection(a, a) = 2.0 / (hi - lo);
      projection(a, 3) = -(hi + lo) / (hi - lo);
    }
    out.view_projection = projection.cast<float>() * view;
    out.window_x = k1[0] - k0[0];
    out.window_y = k1[1] - k0[1];
    out.windowed = true;
    out.view = view;
    out.window_min = Eigen::Vector2f(static_cast<float>(-r + k0[0] * tau), static_cast<float>(-r + k0[1] * tau));
    out.window_max = Eigen::Vector2f(static_cast<float>(-r + k1[0] * tau), static_cast<float>(-r + k1[1] * tau));
    return out;
  }

  // Depth of the shadow casters' front faces (back faces culled: the meshes are closed, and the
  // main pass culls them too) over the texel rectangles in light_dirty_, each cleared first; with
  // `cull`, a caster is drawn only into the rectangles its box reaches.
  void draw_shadow_pass(const FrameState& frame, bool draw_rod, bool cull, const ShadowProjection& shadow) {
    glBindFramebuffer(GL_FRAMEBUFFER, shadow_fbo_);
    glViewport(0, 0, shadow.window_x, shadow.window_y);
    glEnable(GL_SCISSOR_TEST);
    glEnable(GL_DEPTH_TEST);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glFrontFace(GL_CCW);
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.5f, 2.0f);
    glUseProgram(shadow_program_);
    glUniformMatrix4fv(u_shadow_light_vp_, 1, GL_FALSE, shadow.view_projection.data());
    const PixelRect window{0, 0, shadow.limit_x(options_.shadow_map_size), shadow.limit_y(options_.shadow_map_size)};
    caster_rects_.resize(scene_.instances.size());
    for (std::size_t i = 0; i < scene_.instances.size(); ++i) {
      const Eigen::AlignedBox3f& body_box = mesh_bounds_[static_cast<std::size_t>(scene_.instances[i].mesh)];
      caster_rects_[i] = cull ? light_rect(world_box(frame.instance_poses[i], body_box), shadow) : window;
    }
    for (const PixelRect& rect : light_dirty_) {
      scissor(rect);
      glClear(GL_DEPTH_BUFFER_BIT);
    }
    // Each caster once, over the cleared rectangles it reaches (see reach()).
    for (std::size_t i = 0; i < scene_.instances.size(); ++i) {
      const PixelRect box = reach(caster_rects_[i], light_dirty_);
      if (!scene_.instances[i].casts_shadow || box.empty()) continue;
      scissor(box);
      const Eigen::Matrix4f m = frame.instance_poses[i].matrix().cast<float>();
      glUniformMatrix4fv(u_shadow_model_, 1, GL_FALSE, m.data());
      draw(meshes_[static_cast<std::size_t>(scene_.instances[i].mesh)]);
    }
    if (draw_rod) {
      scissor(reach(window, light_dirty_));
      const Eigen::Matrix4f identity = Eigen::Matrix4f::Identity();
      glUniformMatrix4fv(u_shadow_model_, 1, GL_FALSE, identity.data());
      draw(rod_gpu_);
    }
    glDisable(GL_POLYGON_OFFSET_FILL);
    glDisable(GL_SCISSOR_TEST);
  }

  // The shadow-map texels (window coordinates) a world box can cover, two added a side.
  PixelRect light_rect(const Eigen::AlignedBox3f& box, const ShadowProjection& shadow) const {
    Eigen::AlignedBox2f texels;
    for (int c = 0; c < 8 && !box.isEmpty(); ++c) {
      const Eigen::Vector4f p = shadow.view_projection * box.corner(static_cast<Eigen::AlignedBox3f::CornerType>(c)).homogeneous();
      texels.extend(clip_to_pixels(p, shadow.window_x, shadow.window_y));
    }
    return to_pixels(texels, 2.0f, shadow.limit_x(options_.shadow_map_size), shadow.limit_y(options_.shadow_map_size));
  }

  // The main pass over the rectangles in dirty_ (each cleared, then drawn with everything that
  // can reach it: the same draws in the same order as over the whole image).
  void draw_main_pass(const FrameState& frame, const Camera& camera, bool draw_rod, bool cull, const ShadowProjection& shadow,
                      const Eigen::Matrix4f& view_projection) {
    const int w = camera.width, h = camera.height;
    // Colour to attachment 0, object id to attachment 1 (when the mask is read).
    glBindFramebuffer(GL_FRAMEBUFFER, main_fbo_);
    glViewport(0, 0, w, h);
    const GLenum buffers[2] = {GL_COLOR_ATTACHMENT0, options_.read_mask ? GLenum(GL_COLOR_ATTACHMENT1) : GLenum(GL_NONE)};
    glDrawBuffers(2, buffers);
    glEnable(GL_DEPTH_TEST);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glFrontFace(GL_CW);  // the image is drawn upside down (see render_into)
    const Lighting& light = scene_.lighting;
    const Eigen::Vector3f light_direction = light.direction.normalized().cast<float>();
    const Eigen::Vector3f light_position = light.position.cast<float>();
    const Eigen::Vector3f light_color = light.color * light.intensity;
    const Eigen::Vector3f ambient = light.ambient_color * light.ambient_intensity;
    const Eigen::Vector3f eye = camera.position.cast<float>();
    const float spot_cos = static_cast<float>(std::cos(light.spot_cone_deg * std::numbers::pi / 180.0));
    const float shadow_window[2] = {static_cast<float>(shadow.window_x), static_cast<float>(shadow.window_y)};
    light_set_ = light.kind == LightKind::spot ? 1 : 0;
    for (std::size_t variant = 0; variant < 2; ++variant) {  // per-frame uniforms of every program
      for (std::size_t kind = 0; kind < texture_kinds; ++kind) {
        const GLuint program = programs_[light_set_][variant][kind];
        if (program == 0) continue;
        const Uniforms& u = uniforms_[light_set_][variant][kind];
        glUseProgram(program);
        glUniformMatrix4fv(u.view_projection, 1, GL_FALSE, view_projection.data());
        glUniformMatrix4fv(u.light_view_projection, 1, GL_FALSE, shadow.view_projection.data());
        glUniform3fv(u.light_direction, 1, light_direction.data());
        glUniform3fv(u.light_position, 1, light_position.data());
        glUniform1f(u.spot_cos, spot_cos);
        glUniform3fv(u.light_color, 1, light_color.data());
        glUniform3fv(u.ambient, 1, ambient.data());
        glUniform3fv(u.camera_position, 1, eye.data());
        glUniform1i(u.shadow_map, 0);
        glUniform2fv(u.shadow_window, 1, shadow_window);
        glUniform1f(u.shadow_size, static_cast<float>(options_.shadow_map_size));
        glUniform1f(u.shadow_bias, shadow.bias);
      }
    }
    current_kind_ = texture_kinds;  // none: the next set_material binds its program
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, shadow_texture_);

    // Per frame: each instance's screen rectangle (to skip it where it cannot be: `cull`) and each
    // receiver's rectangle where it can be in shadow.
    const PixelRect whole{0, 0, w, h};
    instance_rects_.resize(scene_.instances.size());
    receiver_inside_.resize(scene_.instances.size());
    for (std::size_t i = 0; i < scene_.instances.size(); ++i) {
      const Eigen::AlignedBox3f& body_box = mesh_bounds_[static_cast<std::size_t>(scene_.instances[i].mesh)];
      instance_rects_[i] = cull ? screen_rect(world_box(frame.instance_poses[i], body_box), view_projection, w, h) : whole;
      if (options_.shadows && !scene_.instances[i].casts_shadow) {
        receiver_inside_[i] = shadowed_screen_rect(frame.instance_poses[i], body_box, shadow, view_projection, w, h);
      }
    }
    PixelRect rod_rect = whole, goal_rect = whole;
    if (cull && draw_rod) {
      Eigen::AlignedBox3f rod_box;
      for (const Eigen::AlignedBox3f& b : drawn_.rod_chunks) rod_box.extend(b);
      rod_rect = screen_rect(rod_box, view_projection, w, h);
    }
    if (cull && frame.goal_pose) goal_rect = screen_rect(world_box(*frame.goal_pose, triad_bounds_), view_projection, w, h);

    const Eigen::Vector3f bg = scene_.background_color.cwiseMax(0.0f).cwiseMin(1.0f);
    const float clear_color[4] = {std::pow(bg.x(), 1.0f / 2.2f), std::pow(bg.y(), 1.0f / 2.2f), std::pow(bg.z(), 1.0f / 2.2f), 1.0f};
    const GLuint clear_id[4] = {0, 0, 0, 0};
    const GLfloat clear_depth = 1.0f;
    auto draw_instance = [&](std::size_t i, bool shadowed) {
      const Instance& inst = scene_.instances[i];
      set_material(scene_.materials[static_cast<std::size_t>(inst.material)], shadowed);
      set_model(frame.instance_poses[i]);
      glUniform1ui(current_uniforms().object_id, inst.object_id);
      draw(meshes_[static_cast<std::size_t>(inst.mesh)]);
    };
    glEnable(GL_SCISSOR_TEST);
    for (const PixelRect& rect : dirty_) {
      scissor(rect);
      glClearBufferfv(GL_COLOR, 0, clear_color);
      if (options_.read_mask) glClearBufferuiv(GL_COLOR, 1, clear_id);
      glClearBufferfv(GL_DEPTH, 0, &clear_depth);
    }
    // Rod first, then the instances in draw_order_ (small before large, large receivers such as
    // the floor last): occluders first lets llvmpipe's early depth test skip hidden blocks. Each
    // once, over the cleared rectangles it reaches (see reach()).
    if (const PixelRect box = reach(rod_rect, dirty_); draw_rod && !box.empty()) {
      scissor(box);
      set_material(scene_.materials[static_cast<std::size_t>(scene_.rod.material)], true);
      set_model(math::Pose<double>{});
      glUniform1ui(current_uniforms().object_id, scene_.rod.object_id);
      draw(rod_gpu_);
    }
    for (const std::size_t i : draw_order_) {
      const PixelRect box = reach(instance_rects_[i], dirty_);
      if (box.empty()) continue;
      if (scene_.instances[i].casts_shadow || !options_.shadows) {
        scissor(box);
        draw_instance(i, true);
        continue;
      }
      // A receiver: the shadow lookup only inside the screen rectangle where it can be shadowed,
      // the program without it on the rest (the same pixels: outside the shadow map's window the
      // lookup returns 1).
      for (const PixelRect& r : complement(receiver_inside_[i], w, h)) {
        const PixelRect part = intersect(r, box);
        if (part.empty()) continue;
        scissor(part);
        draw_instance(i, false);
      }
      if (const PixelRect part = intersect(receiver_inside_[i], box); !part.empty()) {
        scissor(part);
        draw_instance(i, true);
      }
    }
    if (const PixelRect box = reach(goal_rect, dirty_); frame.goal_pose && !box.empty()) {
      scissor(box);
      const std::array<Eigen::Vector3f, 3> colors = {Eigen::Vector3f(0.85f, 0.1f, 0.1f), Eigen::Vector3f(0.1f, 0.7f, 0.1f),
                                                     Eigen::Vector3f(0.1f, 0.2f, 0.9f)};
      for (std::size_t a = 0; a < 3; ++a) {
        Material m;
        m.base_color = colors[a];
        set_material(m, true);
        set_model(*frame.goal_pose);
        glUniform1ui(current_uniforms().object_id, scene_.goal_marker.object_id);
        draw(triad_[a]);
      }
    }
    glDisable(GL_SCISSOR_TEST);
  }

  static void scissor(const PixelRect& r) { glScissor(r.x0, r.y0, r.x1 - r.x0, r.y1 - r.y0); }

  // Where a drawable with screen (or shadow-map) rectangle `r` is drawn: the bounding rectangle of
  // its overlaps with the cleared rectangles. Between those, its fragments meet the depth the
  // targets already hold, which is this frame's (nothing there changed), and fail the depth test
  // (GL_LESS: the same fragment, or one behind): drawing once over the bounding rectangle costs
  // one pass over the geometry instead of one per rectangle.
  static PixelRect reach(const PixelRect& r, const std::vector<PixelRect>& cleared) {
    PixelRect box;
    for (const PixelRect& c : cleared) {
      const PixelRect part = intersect(r, c);
      if (part.empty()) continue;
      box = box.empty() ? part
                        : PixelRect{std::min(box.x0, part.x0), std::min(box.y0, part.y0), std::max(box.x1, part.x1), std::max(box.y1, part.y1)};
    }
    return box;
  }

  // Incremental drawing: fills dirty_ with the screen rectangles that changed since the drawn
  // frame and light_dirty_ with the shadow-map texels whose casters changed; refreshes
  // drawn_.rod_chunks to this frame's tube. Every box is taken where the thing was and where it is.
  void collect_changes(const FrameState& frame, bool draw_rod, bool rod_changed, const ShadowProjection& shadow, const Eigen::Matrix4f& view_projection,
                       int w, int h) {
    auto changed = [&](const Eigen::AlignedBox3f& box, bool casts_shadow) {
      dirty_.push_back(screen_rect(box, view_projection, w, h));
      if (casts_shadow && options_.shadows) light_dirty_.push_back(light_rect(box, shadow));
    };
    for (std::size_t i = 0; i < scene_.instances.size(); ++i) {
      const math::Pose<double>& before = drawn_.poses[i];
      const math::Pose<double>& now = frame.instance_poses[i];
      if (before.rotation == now.rotation && before.translation == now.translation) continue;
      const Eigen::AlignedBox3f& body_box = mesh_bounds_[static_cast<std::size_t>(scene_.instances[i].mesh)];
      changed(world_box(before, body_box), scene_.instances[i].casts_shadow);
      changed(world_box(now, body_box), scene_.instances[i].casts_shadow);
    }
    if (rod_changed) {
      // The tube in chunks of rings: a chunk whose vertices changed is redrawn where it was and
      // where it is (the chunk boxes of the drawn frame are kept in drawn_.rod_chunks).
      chunk_scratch_.clear();
      if (draw_rod) rod_chunk_boxes(chunk_scratch_);
      const bool same_layout = drawn_.rod && draw_rod && rod_mesh_.positions.size() == drawn_.rod_positions.size();
      const std::size_t chunks = std::max(chunk_scratch_.size(), drawn_.rod_chunks.size());
      for (std::size_t c = 0; c < chunks; ++c) {
        const bool before = c < drawn_.rod_chunks.size(), now = c < chunk_scratch_.size();
        if (same_layout && same_chunk(c)) continue;
        if (before) changed(drawn_.rod_chunks[c], true);
        if (now) changed(chunk_scratch_[c], true);
      }
      std::swap(drawn_.rod_chunks, chunk_scratch_);
    }
    const bool goal_same = frame.goal_pose.has_value() == drawn_.goal.has_value() &&
                           (!frame.goal_pose || (frame.goal_pose->rotation == drawn_.goal->rotation && frame.goal_pose->translation == drawn_.goal->translation));
    if (!goal_same) {
      if (drawn_.goal) changed(world_box(*drawn_.goal, triad_bounds_), false);
      if (frame.goal_pose) changed(world_box(*frame.goal_pose, triad_bounds_), false);
    }
    merge_rects(light_dirty_, max_light_rects);
    // The pixels whose shadow lookup can read a changed texel: every drawable's box clipped to the
    // prism that the texels (plus two: the 2 x 2 lookup and rounding) sweep along the light.
    const Eigen::Vector2f texel = (shadow.window_max - shadow.window_min).cwiseQuotient(Eigen::Vector2f(shadow.window_x, shadow.window_y));
    for (const PixelRect& r : light_dirty_) {
      const Eigen::Vector2f lo = shadow.window_min + Eigen::Vector2f(r.x0 - 2.0f, r.y0 - 2.0f).cwiseProduct(texel);
      const Eigen::Vector2f hi = shadow.window_min + Eigen::Vector2f(r.x1 + 2.0f, r.y1 + 2.0f).cwiseProduct(texel);
      auto receives = [&](const Eigen::AlignedBox3f& box) {
        const PixelRect p = prism_screen_rect(box, shadow.view, lo, hi, view_projection, w, h);
        if (!p.empty()) dirty_.push_back(p);
      };
      for (std::size_t i = 0; i < scene_.instances.size(); ++i) {
        receives(world_box(frame.instance_poses[i], mesh_bounds_[static_cast<std::size_t>(scene_.instances[i].mesh)]));
      }
      if (draw_rod) {
        for (const Eigen::AlignedBox3f& b : drawn_.rod_chunks) receives(b);
      }
      if (frame.goal_pose) receives(world_box(*frame.goal_pose, triad_bounds_));
    }
  }

  // The tube's vertices (make_tube_into): rings of (sides + 1) along the rod, then the start and
  // the end cap (sides + 2 each, lying on the end rings). Chunk c is rings [c k, (c + 1) k]
  // (k = rod_chunk_rings; the ring shared with the next chunk included, so that the triangles
  // between chunks are inside), with its cap for the end chunks.
  struct ChunkVertices {
    std::size_t ring_first = 0, ring_end = 0, cap_first = 0, cap_end = 0;
  };
  std::size_t rod_chunk_count() const {
    const std::size_t ring = static_cast<std::size_t>(scene_.rod.sides) + 1, cap = ring + 1;
    const std::size_t rings = (rod_mesh_.positions.size() - 2 * cap) / ring;
    return (rings - 1 + rod_chunk_rings - 1) / rod_chunk_rings;
  }
  ChunkVertices rod_chunk(std::size_t c) const {
    const std::size_t ring = static_cast<std::size_t>(scene_.rod.sides) + 1, cap = ring + 1;
    const std::size_t rings_end = rod_mesh_.positions.size() - 2 * cap;
    ChunkVertices v{c * rod_chunk_rings * ring, std::min(rings_end, ((c + 1) * rod_chunk_rings + 1) * ring), rings_end, rings_end};
    if (c == 0) v.cap_end = rings_end + cap;
    if (c + 1 == rod_chunk_count()) {
      v.cap_first = c == 0 ? rings_end : rings_end + cap;
      v.cap_end = rings_end + 2 * cap;
    }
    return v;
  }

  // Whether chunk c of the tube has the drawn frame's positions and normals (same vertex count).
  bool same_chunk(std::size_t c) const {
    const ChunkVertices v = rod_chunk(c);
    auto same = [&](std::size_t first, std::size_t end) {
      for (std::size_t k = first; k < end; ++k) {
        if (rod_mesh_.positions[k] != drawn_.rod_positions[k] || rod_mesh_.normals[k] != drawn_.rod_normals[k]) return false;
      }
      return true;
    };
    return same(v.ring_first, v.ring_end) && same(v.cap_first, v.cap_end);
  }

  // World boxes of the current tube's chunks (their rings: the caps lie inside).
  void rod_chunk_boxes(std::vector<Eigen::AlignedBox3f>& boxes) const {
    boxes.clear();
    for (std::size_t c = 0; c < rod_chunk_count(); ++c) {
      const ChunkVertices v = rod_chunk(c);
      Eigen::AlignedBox3f box;
      for (std::size_t k = v.ring_first; k < v.ring_end; ++k) box.extend(rod_mesh_.positions[k]);
      boxes.push_back(box);
    }
  }

  static Eigen::AlignedBox3f world_box(const math::Pose<double>& pose, const Eigen::AlignedBox3f& body_box) {
    Eigen::AlignedBox3f box;
    if (body_box.isEmpty()) return box;
    const Eigen::Matrix4f model = pose.matrix().cast<float>();
    for (int c = 0; c < 8; ++c) {
      box.extend((model.topLeftCorner<3, 3>() * body_box.corner(static_cast<Eigen::AlignedBox3f::CornerType>(c)) + model.topRightCorner<3, 1>()).eval());
    }
    return box;
  }

  // A clip-space point's position in a width x height viewport, in pixels.
  static Eigen::Vector2f clip_to_pixels(const Eigen::Vector4f& clip, int width, int height) {
    return Eigen::Vector2f((clip.x() / clip.w() + 1.0f) * 0.5f * static_cast<float>(width), (clip.y() / clip.w() + 1.0f) * 0.5f * static_cast<float>(height));
  }

  // Framebuffer pixels covering a set of points given in pixel units, `margin` added a side,
  // clamped to [0, width) x [0, height).
  static PixelRect to_pixels(const Eigen::AlignedBox2f& points, float margin, int width, int height) {
    if (points.isEmpty()) return PixelRect{};
    auto clamp_to = [](float v, int hi) { return static_cast<int>(std::clamp(v, 0.0f, static_cast<float>(hi))); };
    return PixelRect{clamp_to(std::floor(points.min().x()) - margin, width), clamp_to(std::floor(points.min().y()) - margin, height),
                     clamp_to(std::ceil(points.max().x()) + margin, width), clamp_to(std::ceil(points.max().y()) + margin, height)};
  }

  // The pixels a world box can cover: its corners projected, two pixels added a side; the whole
  // image when a corner is not in front of the camera.
  static PixelRect screen_rect(const Eigen::AlignedBox3f& box, const Eigen::Matrix4f& view_projection, int width, int height) {
    if (box.isEmpty()) return PixelRect{};
    Eigen::AlignedBox2f pixels;
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector4f clip = view_projection * box.corner(static_cast<Eigen::AlignedBox3f::CornerType>(c)).homogeneous();
      if (!(clip.w() > 1e-6f)) return PixelRect{0, 0, width, height};
      pixels.extend(clip_to_pixels(clip, width, height));
    }
    return to_pixels(pixels, 2.0f, width, height);
  }

  static PixelRect intersect(const PixelRect& a, const PixelRect& b) {
    return PixelRect{std::max(a.x0, b.x0), std::max(a.y0, b.y0), std::min(a.x1, b.x1), std::min(a.y1, b.y1)};
  }

  static long long area(const PixelRect& r) { return r.empty() ? 0 : static_cast<long long>(r.x1 - r.x0) * (r.y1 - r.y0); }

  // Joins the rectangles into at most max_count: largest first, each joins the kept rectangle it
  // adds the fewest pixels to when that adds none or no slot is left; then kept rectangles join
  // while joining two adds no pixels. Empty rectangles are dropped. O(n max_count).
  static void merge_rects(std::vector<PixelRect>& rects, std::size_t max_count) {
    std::erase_if(rects, [](const PixelRect& r) { return r.empty(); });
    std::sort(rects.begin(), rects.end(), [](const PixelRect& a, const PixelRect& b) { return area(a) > area(b); });
    auto join = [](const PixelRect& a, const PixelRect& b) {
      return PixelRect{std::min(a.x0, b.x0), std::min(a.y0, b.y0), std::max(a.x1, b.x1), std::max(a.y1, b.y1)};
    };
    auto cost = [&](const PixelRect& a, const PixelRect& b) { return area(join(a, b)) - area(a) - area(b); };
    std::size_t kept = 0;
    for (std::size_t i = 0; i < rects.size(); ++i) {
      std::size_t best = 0;
      long long best_cost = std::numeric_limits<long long>::max();
      for (std::size_t j = 0; j < kept; ++j) {
        if (const long long c = cost(rects[j], rects[i]); c < best_cost) {
          best_cost = c;
          best = j;
        }
      }
      if (kept < std::max<std::size_t>(max_count, 1) && best_cost > 0) {
        rects[kept++] = rects[i];
      } else {
        rects[best] = join(rects[best], rects[i]);
      }
    }
    rects.resize(kept);
    for (bool joined = true; joined;) {
      joined = false;
      for (std::size_t a = 0; a < rects.size() && !joined; ++a) {
        for (std::size_t b = a + 1; b < rects.size() && !joined; ++b) {
          if (cost(rects[a], rects[b]) > 0) continue;
          rects[a] = join(rects[a], rects[b]);
          rects.erase(rects.begin() + static_cast<std::ptrdiff_t>(b));
          joined = true;
        }
      }
    }
  }

  // The frame the targets hold (incremental drawing).
  struct DrawnFrame {
    bool valid = false;
    std::size_t camera = 0;
    std::vector<math::Pose<double>> poses;
    bool rod = false;
    Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> rod_nodes;
    Eigen::Matrix<double, Eigen::Dynamic, 9, Eigen::RowMajor> rod_directors;
    double rod_radius = 0;
    std::vector<Eigen::Vector3f> rod_positions, rod_normals;  // the drawn tube's vertices
    std::vector<Eigen::AlignedBox3f> rod_chunks;              // and its chunks' world boxes
    std::optional<math::Pose<double>> goal;
    Eigen::Matrix4f shadow_view_projection = Eigen::Matrix4f::Zero();

    bool same_rod(const RodShape& r) const {
      return r.radius == rod_radius && r.nodes.rows() == rod_nodes.rows() && r.directors.rows() == rod_directors.rows() &&
             (r.nodes.array() == rod_nodes.array()).all() && (r.directors.array() == rod_directors.array()).all();
    }
    void record(const FrameState& f, bool drew_rod, const Mesh& tube, std::size_t camera_index, const Eigen::Matrix4f& shadow_vp) {
      poses = f.instance_poses;
      rod = drew_rod;
      if (drew_rod) {
        rod_nodes = f.rod.nodes;
        rod_directors = f.rod.directors;
        rod_radius = f.rod.radius;
        rod_positions = tube.positions;
        rod_normals = tube.normals;
      }
      goal = f.goal_pose;
      camera = camera_index;
      shadow_view_projection = shadow_vp;
      valid = true;
    }
  };

  const Uniforms& current_uniforms() const { return uniforms_[light_set_][current_shadowed_][current_kind_]; }

  // Selects the program of the material's texture kind (with the shadow lookup or without) and
  // sets the material's uniforms.
  void set_material(const Material& m, bool shadowed) {
    const auto kind = static_cast<std::size_t>(m.texture);
    const std::size_t variant = shadowed && options_.shadows ? 1 : 0;
    if (kind != current_kind_ || variant != current_shadowed_) {
      glUseProgram(programs_[light_set_][variant][kind]);
      current_kind_ = kind;
      current_shadowed_ = variant;
    }
    const Uniforms& u = current_uniforms();
    glUniform3fv(u.base_color, 1, m.base_color.data());
    glUniform3fv(u.secondary_color, 1, m.secondary_color.data());
    glUniform1f(u.texture_scale, m.texture_scale);
    glUniform1f(u.texture_strength, m.texture_strength);
    glUniform1f(u.specular, m.specular);
    glUniform1f(u.shininess, m.shininess);
  }

  void set_model(const math::Pose<double>& pose) {
    const Eigen::Matrix4f m = pose.matrix().cast<float>();
    const Eigen::Matrix3f n = pose.rotation.cast<float>();  // orthonormal: the normal matrix is the rotation
    glUniformMatrix4fv(current_uniforms().model, 1, GL_FALSE, m.data());
    glUniformMatrix3fv(current_uniforms().normal_matrix, 1, GL_FALSE, n.data());
  }

  static void draw(const detail_gl::GpuMesh& g) {
    if (g.index_count == 0) return;
    glBindVertexArray(g.vao);
    glDrawElements(GL_TRIANGLES, g.index_count, GL_UNSIGNED_INT, nullptr);
  }

  void create_shadow_map() {
    glGenTextures(1, &shadow_texture_);
    glBindTexture(GL_TEXTURE_2D, shadow_texture_);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, options_.shadow_map_size, options_.shadow_map_size, 0, GL_DEPTH_COMPONENT, GL_FLOAT, nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    glGenFramebuffers(1, &shadow_fbo_);
    glBindFramebuffer(GL_FRAMEBUFFER, shadow_fbo_);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, shadow_texture_, 0);
    glDrawBuffer(GL_NONE);
    glReadBuffer(GL_NONE);
    check_framebuffer("shadow map");
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
  }

  static void check_framebuffer(const char* what) {
    const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE) manisoft::detail::fail("GlRenderer: the ", what, " framebuffer is incomplete (status 0x", std::hex, status, ")");
  }

  // Colour (RGBA8), id (R16UI) and depth (24-bit) renderbuffers of the camera's size.
  void ensure_targets(int width, int height) {
    if (width == target_width_ && height == target_height_) return;
    destroy_targets();
    const int samples = options_.msaa_samples > 1 ? options_.msaa_samples : 0;
    auto make_fbo = [&](GLuint& fbo, std::array<GLuint, 3>& rbs, int s) {
      glGenFramebuffers(1, &fbo);
      glBindFramebuffer(GL_FRAMEBUFFER, fbo);
      glGenRenderbuffers(3, rbs.data());
      const GLenum formats[3] = {GL_RGBA8, GL_R16UI, GL_DEPTH_COMPONENT24};
      const GLenum attachments[3] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_DEPTH_ATTACHMENT};
      for (int i = 0; i < 3; ++i) {
        glBindRenderbuffer(GL_RENDERBUFFER, rbs[static_cast<std::size_t>(i)]);
        glRenderbufferStorageMultisample(GL_RENDERBUFFER, s, formats[i], width, height);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, attachments[i], GL_RENDERBUFFER, rbs[static_cast<std::size_t>(i)]);
      }
      check_framebuffer(s > 0 ? "multisampled" : "main");
    };
    drawn_.valid = false;
    make_fbo(main_fbo_, main_rbs_, samples);
    if (samples > 0) make_fbo(resolve_fbo_, resolve_rbs_, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    target_width_ = width;
    target_height_ = height;
  }

  void destroy_targets() {
    if (main_fbo_) glDeleteFramebuffers(1, &main_fbo_);
    if (resolve_fbo_) glDeleteFramebuffers(1, &resolve_fbo_);
    if (main_rbs_[0]) glDeleteRenderbuffers(3, main_rbs_.data());
    if (resolve_rbs_[0]) glDeleteRenderbuffers(3, resolve_rbs_.data());
    main_fbo_ = resolve_fbo_ = 0;
    main_rbs_ = {0, 0, 0};
    resolve_rbs_ = {0, 0, 0};
    target_width_ = target_height_ = 0;
  }

  void release() {
    if (!context_) return;
    context_->make_current();
    for (auto& g : meshes_) detail_gl::destroy(g);
    for (auto& g : triad_) detail_gl::destroy(g);
    detail_gl::destroy(rod_gpu_);
    destroy_targets();
    if (shadow_fbo_) glDeleteFramebuffers(1, &shadow_fbo_);
    if (shadow_texture_) glDeleteTextures(1, &shadow_texture_);
    for (auto& light_set : programs_) {
      for (auto& set : light_set) {
        for (GLuint& p : set) {
          if (p) glDeleteProgram(p);
          p = 0;
        }
      }
    }
    if (shadow_program_) glDeleteProgram(shadow_program_);
    shadow_fbo_ = shadow_texture_ = shadow_program_ = 0;
    context_.reset();
  }

  GlRendererOptions options_;
  std::unique_ptr<EglContext> context_;
  SceneDescription scene_;
  bool have_scene_ = false;
  static constexpr std::size_t texture_kinds = 6;  // TextureKind none..noise
  bool gather_ = false;                            // GLSL 4.00: textureGather for the shadow tap
  std::array<std::array<std::array<GLuint, texture_kinds>, 2>, 2> programs_{};  // [light kind][shadow lookup][texture kind]
  std::array<std::array<std::array<Uniforms, texture_kinds>, 2>, 2> uniforms_{};
  std::size_t light_set_ = 0;                       // light kind of the frame being drawn
  std::size_t current_kind_ = 0;                    // program in use: texture kind
  std::size_t current_shadowed_ = 0;                // and shadow variant
  GLuint shadow_program_ = 0;
  GLint u_shadow_model_ = -1, u_shadow_light_vp_ = -1;
  std::vector<detail_gl::GpuMesh> meshes_;
  std::vector<Eigen::AlignedBox3f> mesh_bounds_;  // body frame
  std::vector<std::size_t> draw_order_;           // instance indices in main-pass order
  std::array<detail_gl::GpuMesh, 3> triad_{};
  detail_gl::GpuMesh rod_gpu_;
  Mesh rod_mesh_;
  GLuint shadow_fbo_ = 0, shadow_texture_ = 0;
  GLuint main_fbo_ = 0, resolve_fbo_ = 0;
  std::array<GLuint, 3> main_rbs_{0, 0, 0}, resolve_rbs_{0, 0, 0};
  int target_width_ = 0, target_height_ = 0;
  // Incremental drawing (GlRendererOptions::incremental).
  static constexpr int rod_chunk_rings = 8;            // tube rings per chunk (two elements at 4 rings each)
  static constexpr std::size_t max_dirty_rects = 12;   // screen rectangles cleared per frame, at most
  DrawnFrame drawn_;
  DrawStats stats_;
  Eigen::AlignedBox3f triad_bounds_;                   // the goal marker, body frame
  static constexpr std::size_t max_light_rects = 8;    // shadow-map rectangles cleared per frame, at most
  std::vector<PixelRect> dirty_, instance_rects_, receiver_inside_, light_dirty_, caster_rects_;
  std::vector<Eigen::AlignedBox3f> chunk_scratch_;
  std::vector<std::uint32_t> scratch_depth_;
  std::vector<std::array<std::uint8_t, 4>> scratch_rgba_;
  std::vector<float> upload_scratch_;
};

}  // namespace manisoft::render
