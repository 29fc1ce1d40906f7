// The in-process OpenGL renderer (ManiSoft paper, section 3.2: the image V_t the policy sees each
// step), a render::Renderer (renderer.hpp): set_scene() once, render() per frame. It composes
//   gl_shaders.hpp     the GLSL sources (Blinn-Phong, procedural textures, shadow lookup),
//   gl_resources.hpp   programs, meshes on the GPU, the shadow map and the render targets,
//   gl_projection.hpp  the camera's and the light's projections,
//   dirty_rects.hpp    the rectangles an incremental frame clears and redraws (pure geometry),
//   drawn_frame.hpp    what the targets hold between frames,
//   gl_readback.hpp    colour, ids and linearised depth read back into a RenderOutput,
// into framebuffer objects of an EGL context without a display (egl_context.hpp). Same inputs give
// the same pixels.
//
// Speed on a CPU (Mesa llvmpipe, BENCHMARKS.md "Renderer"): the shaders are specialised at compile
// time (texture kind, light kind, shadows) and kept short; a directional light's shadow map is
// rendered only over the shadow casters' extent (a sub-rectangle of the map at the full map's
// texel size, so the shadows look the same as with the whole map); the shadow pass culls back
// faces; receivers that cast no shadow (the floor) run the shadow lookup only in the screen
// rectangle where the map's window can shadow them (the program without it elsewhere: the same
// pixels); opaque meshes are drawn small before large, receivers last (early depth test); the id
// target is drawn only when the mask is read; glibc's heap trimming is relaxed
// (GlRendererOptions::keep_freed_heap). Between frames only what changed is redrawn
// (GlRendererOptions::incremental): rectangles around the moved instances, tube chunks and goal
// marker (before and after), the shadow map's texels their casters cover, and the pixels whose
// shadow lookup reads those texels (each drawable's box clipped to the prism those texels sweep
// along the light) are cleared, then each drawable that reaches them is drawn once under a
// scissor; the targets keep every other pixel, which a full redraw would draw identically (there
// a redrawn fragment fails the depth test).
#pragma once

#include <GL/glcorearb.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <ios>
#include <memory>
#include <numbers>
#include <string>
#include <vector>
#if defined(__GLIBC__)  // defined by the standard headers above
#include <malloc.h>     // mallopt (GlRendererOptions::keep_freed_heap)
#endif

#include "manisoft/core/error.hpp"
#include "manisoft/render/camera.hpp"
#include "manisoft/render/dirty_rects.hpp"
#include "manisoft/render/drawn_frame.hpp"
#include "manisoft/render/egl_context.hpp"
#include "manisoft/render/gl_projection.hpp"
#include "manisoft/render/gl_readback.hpp"
#include "manisoft/render/gl_resources.hpp"
#include "manisoft/render/gl_shaders.hpp"
#include "manisoft/render/image.hpp"
#include "manisoft/render/mesh_builders.hpp"
#include "manisoft/render/renderer.hpp"
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


/// OpenGL renderer: set_scene() once, render() per frame. Not copyable; uses its EGL context on
/// the calling thread. Construction throws manisoft::Error when no EGL display or context can be
/// had, or for invalid options.
class GlRenderer {
 public:
  using Options = GlRendererOptions;

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
      if (options_.shadows) shadow_map_.create(options_.shadow_map_size);
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
    validate(scene);
    drawn_.valid = false;  // the targets no longer hold a frame of the scene being set
    const std::size_t light_set = scene.lighting.kind == LightKind::spot ? 1 : 0;
    build_programs(light_set);
    // Receivers (instances that cast no shadow, e.g. the floor) are drawn without the shadow
    // lookup where they cannot be in shadow (draw_instances): their programs without shadows.
    if (options_.shadows) {
      for (const Instance& inst : scene.instances) {
        const auto kind = static_cast<std::size_t>(scene.materials[static_cast<std::size_t>(inst.material)].texture);
        if (!inst.casts_shadow) ensure_program(light_set, 0, kind);
      }
    }
    upload_meshes(scene);
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
    validate_frame(frame, camera_index);
    const Camera& camera = scene_.cameras[camera_index];
    const CameraModel model = camera_model(camera);
    context_->make_current();
    if (!targets_.has_size(camera.width, camera.height)) {
      drawn_.valid = false;
      targets_.create(camera.width, camera.height, options_.msaa_samples > 1 ? options_.msaa_samples : 0);
    }
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
    const Eigen::Matrix4f view_projection = detail_gl::camera_view_projection(camera, model);
    // What to draw: the whole image, or (incremental) the rectangles around what changed; the
    // shadow map's window, or its texels that changed casters cover (before and after).
    const bool incremental = keep && (!options_.shadows || (shadow.windowed && shadow.view_projection == drawn_.shadow_view_projection));
    plan_frame(frame, draw_rod, rod_changed, incremental, shadow, view_projection, camera.width, camera.height);
    if (!changes_.texels.empty()) draw_shadow_pass(frame, draw_rod, incremental, shadow);
    if (!changes_.screen.empty()) draw_main_pass(frame, camera, draw_rod, incremental, shadow, view_projection);
    // Resolve MSAA, then read back (rows top first: the image was drawn upside down).
    const GLuint read_fbo = options_.msaa_samples > 1
                                ? detail_gl::resolve_msaa(targets_, camera.width, camera.height, options_.read_mask, options_.read_depth)
                                : targets_.main_fbo;
    glFrontFace(GL_CCW);
    read_back_.read(read_fbo, camera, model, options_.read_mask, options_.read_depth, out);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    const GLenum error = glGetError();
    if (error != GL_NO_ERROR) manisoft::detail::fail("GlRenderer::render: OpenGL error 0x", std::hex, error);
    if (options_.incremental) drawn_.record(frame, draw_rod, rod_mesh_, camera_index, shadow.view_projection);
  }

 private:
  using PixelRect = rects::PixelRect;
  using ShadowProjection = detail_gl::ShadowProjection;

  // Compiles the main programs of one light kind (0 directional, 1 spot), one per texture kind,
  // with shadows when the options ask for them.
  void build_programs(std::size_t light_set) {
    for (std::size_t kind = 0; kind < texture_kinds; ++kind) ensure_program(light_set, options_.shadows ? 1 : 0, kind);
  }

  // Compiles one main program variant unless it exists.
  void ensure_program(std::size_t light_set, std::size_t shadowed, std::size_t kind) {
    if (programs_[light_set][shadowed][kind] != 0) return;
    const GLuint program = detail_gl::link(detail_gl::main_vertex_shader, detail_gl::main_fragment_source(kind, shadowed, light_set, gather_));
    programs_[light_set][shadowed][kind] = program;
    uniforms_[light_set][shadowed][kind] = detail_gl::main_uniforms(program);
  }

  // The scene's meshes and the goal marker's triad on the GPU, with their body-frame boxes.
  void upload_meshes(const SceneDescription& scene) {
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
  }

  void validate_frame(const FrameState& frame, std::size_t camera_index) const {
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
  }

  // The shadow map's projection this frame: a spot light's frustum, or a directional light's
  // window over the shadow casters' extent seen from the light (gl_projection.hpp).
  ShadowProjection shadow_projection(const FrameState& frame, bool draw_rod) const {
    const Lighting& l = scene_.lighting;
    if (l.kind != LightKind::directional) return detail_gl::spot_shadow_projection(l, options_.shadow_map_size);
    const Eigen::Matrix4f view = detail_gl::directional_light_view(l);
    const Eigen::AlignedBox2f extent = detail_gl::casters_extent(scene_, mesh_bounds_, frame.instance_poses, draw_rod ? &rod_mesh_ : nullptr, view);
    return detail_gl::directional_shadow_projection(l, view, extent, options_.shadow_map_size);
  }

  // Fills changes_ (screen rectangles, merged, and shadow-map texels) with what this frame draws,
  // and the statistics.
  void plan_frame(const FrameState& frame, bool draw_rod, bool rod_changed, bool incremental, const ShadowProjection& shadow,
                  const Eigen::Matrix4f& view_projection, int w, int h) {
    changes_.screen.clear();
    changes_.texels.clear();
    if (incremental) {
      const detail_gl::Drawables drawables{scene_, mesh_bounds_, triad_bounds_, rod_mesh_};
      const detail_gl::DrawTarget target{view_projection, w, h, options_.shadows ? &shadow : nullptr, options_.shadow_map_size};
      detail_gl::collect_changes(drawables, target, drawn_, frame, draw_rod, rod_changed, max_light_rects, changes_);
    } else {
      changes_.screen.push_back(PixelRect{0, 0, w, h});
      // The window and one texel beyond it: a bilinear tap at its edge reads it.
      if (options_.shadows) changes_.texels.push_back(PixelRect{0, 0, shadow.limit_x(options_.shadow_map_size), shadow.limit_y(options_.shadow_map_size)});
      if (draw_rod) {
        detail_gl::rod_chunk_boxes(rod_mesh_, scene_.rod.sides, drawn_.rod_chunks);
      } else {
        drawn_.rod_chunks.clear();
      }
    }
    rects::merge_rects(changes_.screen, max_dirty_rects);
    stats_ = DrawStats{!incremental, changes_.screen.size(), 0, 0};
    for (const PixelRect& r : changes_.screen) stats_.pixels += static_cast<std::size_t>(rects::area(r));
    for (const PixelRect& r : changes_.texels) stats_.shadow_texels += static_cast<std::size_t>(rects::area(r));
  }

  // Depth of the shadow casters' front faces (back faces culled: the meshes are closed, and the
  // main pass culls them too) over the texel rectangles in changes_.texels, each cleared first; with
  // `cull`, a caster is drawn only into the rectangles its box reaches.
  void draw_shadow_pass(const FrameState& frame, bool draw_rod, bool cull, const ShadowProjection& shadow) {
    glBindFramebuffer(GL_FRAMEBUFFER, shadow_map_.fbo);
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
      caster_rects_[i] = cull ? rects::shadow_texel_rect(rects::world_box(frame.instance_poses[i], body_box), shadow, options_.shadow_map_size) : window;
    }
    for (const PixelRect& rect : changes_.texels) {
      scissor(rect);
      glClear(GL_DEPTH_BUFFER_BIT);
    }
    // Each caster once, over the cleared rectangles it reaches (rects::reach).
    for (std::size_t i = 0; i < scene_.instances.size(); ++i) {
      const PixelRect box = rects::reach(caster_rects_[i], changes_.texels);
      if (!scene_.instances[i].casts_shadow || box.empty()) continue;
      scissor(box);
      const Eigen::Matrix4f m = frame.instance_poses[i].matrix().cast<float>();
      glUniformMatrix4fv(u_shadow_model_, 1, GL_FALSE, m.data());
      detail_gl::draw(meshes_[static_cast<std::size_t>(scene_.instances[i].mesh)]);
    }
    if (draw_rod) {
      scissor(rects::reach(window, changes_.texels));
      const Eigen::Matrix4f identity = Eigen::Matrix4f::Identity();
      glUniformMatrix4fv(u_shadow_model_, 1, GL_FALSE, identity.data());
      detail_gl::draw(rod_gpu_);
    }
    glDisable(GL_POLYGON_OFFSET_FILL);
    glDisable(GL_SCISSOR_TEST);
  }

  // The main pass over the rectangles in changes_.screen (each cleared, then drawn with everything that
  // can reach it: the same draws in the same order as over the whole image).
  void draw_main_pass(const FrameState& frame, const Camera& camera, bool draw_rod, bool cull, const ShadowProjection& shadow,
                      const Eigen::Matrix4f& view_projection) {
    const int w = camera.width, h = camera.height;
    // Colour to attachment 0, object id to attachment 1 (when the mask is read).
    glBindFramebuffer(GL_FRAMEBUFFER, targets_.main_fbo);
    glViewport(0, 0, w, h);
    const GLenum buffers[2] = {GL_COLOR_ATTACHMENT0, options_.read_mask ? GLenum(GL_COLOR_ATTACHMENT1) : GLenum(GL_NONE)};
    glDrawBuffers(2, buffers);
    glEnable(GL_DEPTH_TEST);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glFrontFace(GL_CW);  // the image is drawn upside down (detail_gl::camera_view_projection)
    set_frame_uniforms(camera, shadow, view_projection);
    const PixelRect whole{0, 0, w, h};
    PixelRect rod_rect = whole, goal_rect = whole;
    screen_rects(frame, cull, shadow, view_projection, w, h);
    if (cull && draw_rod) {
      Eigen::AlignedBox3f rod_box;
      for (const Eigen::AlignedBox3f& b : drawn_.rod_chunks) rod_box.extend(b);
      rod_rect = rects::screen_rect(rod_box, view_projection, w, h);
    }
    if (cull && frame.goal_pose) goal_rect = rects::screen_rect(rects::world_box(*frame.goal_pose, triad_bounds_), view_projection, w, h);
    glEnable(GL_SCISSOR_TEST);
    clear_dirty();
    // Rod first, then the instances in draw_order_ (small before large, large receivers such as
    // the floor last): occluders first lets llvmpipe's early depth test skip hidden blocks. Each
    // once, over the cleared rectangles it reaches (rects::reach).
    if (const PixelRect box = rects::reach(rod_rect, changes_.screen); draw_rod && !box.empty()) {
      scissor(box);
      set_material(scene_.materials[static_cast<std::size_t>(scene_.rod.material)], true);
      set_model(math::Pose<double>{});
      glUniform1ui(current_uniforms().object_id, scene_.rod.object_id);
      detail_gl::draw(rod_gpu_);
    }
    draw_instances(frame, w, h);
    if (const PixelRect box = rects::reach(goal_rect, changes_.screen); frame.goal_pose && !box.empty()) draw_goal(*frame.goal_pose, box);
    glDisable(GL_SCISSOR_TEST);
  }

  // The uniforms that change per frame, in every program of the frame's light kind.
  void set_frame_uniforms(const Camera& camera, const ShadowProjection& shadow, const Eigen::Matrix4f& view_projection) {
    const Lighting& light = scene_.lighting;
    const Eigen::Vector3f light_direction = light.direction.normalized().cast<float>();
    const Eigen::Vector3f light_position = light.position.cast<float>();
    const Eigen::Vector3f light_color = light.color * light.intensity;
    const Eigen::Vector3f ambient = light.ambient_color * light.ambient_intensity;
    const Eigen::Vector3f eye = camera.position.cast<float>();
    const float spot_cos = static_cast<float>(std::cos(light.spot_cone_deg * std::numbers::pi / 180.0));
    const float shadow_window[2] = {static_cast<float>(shadow.window_x), static_cast<float>(shadow.window_y)};
    light_set_ = light.kind == LightKind::spot ? 1 : 0;
    for (std::size_t variant = 0; variant < 2; ++variant) {
      for (std::size_t kind = 0; kind < texture_kinds; ++kind) {
        const GLuint program = programs_[light_set_][variant][kind];
        if (program == 0) continue;
        const detail_gl::Uniforms& u = uniforms_[light_set_][variant][kind];
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
    glBindTexture(GL_TEXTURE_2D, shadow_map_.texture);
  }

  // Each instance's screen rectangle (to skip it where it cannot be: `cull`) and each receiver's
  // rectangle where it can be in shadow.
  void screen_rects(const FrameState& frame, bool cull, const ShadowProjection& shadow, const Eigen::Matrix4f& view_projection, int w, int h) {
    const PixelRect whole{0, 0, w, h};
    instance_rects_.resize(scene_.instances.size());
    receiver_inside_.resize(scene_.instances.size());
    for (std::size_t i = 0; i < scene_.instances.size(); ++i) {
      const Eigen::AlignedBox3f& body_box = mesh_bounds_[static_cast<std::size_t>(scene_.instances[i].mesh)];
      instance_rects_[i] = cull ? rects::screen_rect(rects::world_box(frame.instance_poses[i], body_box), view_projection, w, h) : whole;
      if (options_.shadows && !scene_.instances[i].casts_shadow) {
        receiver_inside_[i] = rects::shadowed_screen_rect(frame.instance_poses[i], body_box, shadow, view_projection, w, h);
      }
    }
  }

  // Clears colour (to the background), ids (when read) and depth in every rectangle of changes_.screen.
  void clear_dirty() {
    const Eigen::Vector3f bg = scene_.background_color.cwiseMax(0.0f).cwiseMin(1.0f);
    const float clear_color[4] = {std::pow(bg.x(), 1.0f / 2.2f), std::pow(bg.y(), 1.0f / 2.2f), std::pow(bg.z(), 1.0f / 2.2f), 1.0f};
    const GLuint clear_id[4] = {0, 0, 0, 0};
    const GLfloat clear_depth = 1.0f;
    for (const PixelRect& rect : changes_.screen) {
      scissor(rect);
      glClearBufferfv(GL_COLOR, 0, clear_color);
      if (options_.read_mask) glClearBufferuiv(GL_COLOR, 1, clear_id);
      glClearBufferfv(GL_DEPTH, 0, &clear_depth);
    }
  }

  // The instances in draw_order_, each over the cleared rectangles it reaches. A receiver gets the
  // shadow lookup only inside the screen rectangle where it can be shadowed, the program without
  // it on the rest (the same pixels: outside the shadow map's window the lookup returns 1).
  void draw_instances(const FrameState& frame, int w, int h) {
    for (const std::size_t i : draw_order_) {
      const PixelRect box = rects::reach(instance_rects_[i], changes_.screen);
      if (box.empty()) continue;
      if (scene_.instances[i].casts_shadow || !options_.shadows) {
        scissor(box);
        draw_instance(frame, i, true);
        continue;
      }
      for (const PixelRect& r : rects::complement(receiver_inside_[i], w, h)) {
        const PixelRect part = rects::intersect(r, box);
        if (part.empty()) continue;
        scissor(part);
        draw_instance(frame, i, false);
      }
      if (const PixelRect part = rects::intersect(receiver_inside_[i], box); !part.empty()) {
        scissor(part);
        draw_instance(frame, i, true);
      }
    }
  }

  void draw_instance(const FrameState& frame, std::size_t i, bool shadowed) {
    const Instance& inst = scene_.instances[i];
    set_material(scene_.materials[static_cast<std::size_t>(inst.material)], shadowed);
    set_model(frame.instance_poses[i]);
    glUniform1ui(current_uniforms().object_id, inst.object_id);
    detail_gl::draw(meshes_[static_cast<std::size_t>(inst.mesh)]);
  }

  // The goal marker's three axes (x red, y green, z blue) under the scissor `box`.
  void draw_goal(const math::Pose<double>& goal, const PixelRect& box) {
    scissor(box);
    const std::array<Eigen::Vector3f, 3> colors = {Eigen::Vector3f(0.85f, 0.1f, 0.1f), Eigen::Vector3f(0.1f, 0.7f, 0.1f),
                                                   Eigen::Vector3f(0.1f, 0.2f, 0.9f)};
    for (std::size_t a = 0; a < 3; ++a) {
      Material m;
      m.base_color = colors[a];
      set_material(m, true);
      set_model(goal);
      glUniform1ui(current_uniforms().object_id, scene_.goal_marker.object_id);
      detail_gl::draw(triad_[a]);
    }
  }

  static void scissor(const PixelRect& r) { glScissor(r.x0, r.y0, r.x1 - r.x0, r.y1 - r.y0); }

  const detail_gl::Uniforms& current_uniforms() const { return uniforms_[light_set_][current_shadowed_][current_kind_]; }

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
    const detail_gl::Uniforms& u = current_uniforms();
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

  /// Deletes the GL objects and the context. From a thread the context cannot be made current on
  /// (it is current on another one) the objects are left to the context, which EGL destroys once
  /// it is current nowhere: a renderer may be destroyed on any thread.
  void release() noexcept {
    if (!context_) return;
    if (context_->try_make_current()) {
      for (auto& g : meshes_) detail_gl::destroy(g);
      for (auto& g : triad_) detail_gl::destroy(g);
      detail_gl::destroy(rod_gpu_);
      targets_.destroy();
      shadow_map_.destroy();
      for (auto& light_set : programs_) {
        for (auto& set : light_set) {
          for (GLuint& p : set) {
            if (p) glDeleteProgram(p);
            p = 0;
          }
        }
      }
      if (shadow_program_) glDeleteProgram(shadow_program_);
      shadow_program_ = 0;
    }
    context_.reset();
  }

  GlRendererOptions options_;
  std::unique_ptr<EglContext> context_;
  SceneDescription scene_;
  bool have_scene_ = false;
  static constexpr std::size_t texture_kinds = 6;  // TextureKind none..noise
  bool gather_ = false;                            // GLSL 4.00: textureGather for the shadow tap
  std::array<std::array<std::array<GLuint, texture_kinds>, 2>, 2> programs_{};  // [light kind][shadow lookup][texture kind]
  std::array<std::array<std::array<detail_gl::Uniforms, texture_kinds>, 2>, 2> uniforms_{};
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
  detail_gl::ShadowMap shadow_map_;
  detail_gl::RenderTargets targets_;
  detail_gl::ReadBack read_back_;
  // Incremental drawing (GlRendererOptions::incremental).
  static constexpr std::size_t max_dirty_rects = 12;   // screen rectangles cleared per frame, at most
  static constexpr std::size_t max_light_rects = 8;    // shadow-map rectangles cleared per frame, at most
  detail_gl::DrawnFrame drawn_;
  DrawStats stats_;
  Eigen::AlignedBox3f triad_bounds_;                   // the goal marker, body frame
  detail_gl::FrameChanges changes_;                   // what this frame clears and redraws
  std::vector<PixelRect> instance_rects_, receiver_inside_, caster_rects_;
  std::vector<float> upload_scratch_;
};

static_assert(Renderer<GlRenderer>);

}  // namespace manisoft::render
