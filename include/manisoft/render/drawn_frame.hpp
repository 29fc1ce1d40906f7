// What the renderer's targets hold between frames (gl_renderer.hpp, GlRendererOptions::incremental)
// and what changed since: the drawn frame (instance poses, the rod's shape and its tube's
// vertices, the goal pose, the shadow map's projection); the tube split into chunks of rings, so
// that only the chunks whose vertices changed are redrawn; and collect_changes, the screen
// rectangles and shadow-map texels a frame clears and redraws (dirty_rects.hpp for the
// geometry). Pure data and functions, no GL.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

#include "manisoft/math/se3.hpp"
#include "manisoft/render/dirty_rects.hpp"
#include "manisoft/render/gl_projection.hpp"
#include "manisoft/render/scene.hpp"

namespace manisoft::render::detail_gl {

/// Tube rings per chunk (two elements at 4 rings each).
inline constexpr int rod_chunk_rings = 8;

/// The tube's vertices (make_tube_into, `sides` around): rings of (sides + 1) along the rod, then
/// the start and the end cap (sides + 2 each, lying on the end rings). Chunk c is rings
/// [c k, (c + 1) k] (k = rod_chunk_rings; the ring shared with the next chunk included, so that
/// the triangles between chunks are inside), with its cap for the end chunks.
struct ChunkVertices {
  std::size_t ring_first = 0, ring_end = 0, cap_first = 0, cap_end = 0;
};

inline std::size_t rod_chunk_count(const Mesh& tube, int sides) {
  const std::size_t ring = static_cast<std::size_t>(sides) + 1, cap = ring + 1;
  const std::size_t rings = (tube.positions.size() - 2 * cap) / ring;
  return (rings - 1 + rod_chunk_rings - 1) / rod_chunk_rings;
}

inline ChunkVertices rod_chunk(const Mesh& tube, int sides, std::size_t c) {
  const std::size_t ring = static_cast<std::size_t>(sides) + 1, cap = ring + 1;
  const std::size_t rings_end = tube.positions.size() - 2 * cap;
  ChunkVertices v{c * rod_chunk_rings * ring, std::min(rings_end, ((c + 1) * rod_chunk_rings + 1) * ring), rings_end, rings_end};
  if (c == 0) v.cap_end = rings_end + cap;
  if (c + 1 == rod_chunk_count(tube, sides)) {
    v.cap_first = c == 0 ? rings_end : rings_end + cap;
    v.cap_end = rings_end + 2 * cap;
  }
  return v;
}

/// World boxes of a tube's chunks (their rings: the caps lie inside).
inline void rod_chunk_boxes(const Mesh& tube, int sides, std::vector<Eigen::AlignedBox3f>& boxes) {
  boxes.clear();
  for (std::size_t c = 0; c < rod_chunk_count(tube, sides); ++c) {
    const ChunkVertices v = rod_chunk(tube, sides, c);
    Eigen::AlignedBox3f box;
    for (std::size_t k = v.ring_first; k < v.ring_end; ++k) box.extend(tube.positions[k]);
    boxes.push_back(box);
  }
}

/// The frame the targets hold.
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

  /// Whether chunk c of `tube` has the drawn tube's positions and normals (same vertex count).
  bool same_chunk(const Mesh& tube, int sides, std::size_t c) const {
    const ChunkVertices v = rod_chunk(tube, sides, c);
    auto same = [&](std::size_t first, std::size_t end) {
      for (std::size_t k = first; k < end; ++k) {
        if (tube.positions[k] != rod_positions[k] || tube.normals[k] != rod_normals[k]) return false;
      }
      return true;
    };
    return same(v.ring_first, v.ring_end) && same(v.cap_first, v.cap_end);
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

/// The drawables of a scene: its instances and rod, its meshes' body-frame boxes, the goal
/// marker's body-frame box, and this frame's tube.
struct Drawables {
  const SceneDescription& scene;
  const std::vector<Eigen::AlignedBox3f>& mesh_bounds;
  const Eigen::AlignedBox3f& triad_bounds;
  const Mesh& tube;
};

/// Where a frame is drawn: the camera's view-projection and image size; the shadow map's
/// projection (null without shadows) and texels a side.
struct DrawTarget {
  const Eigen::Matrix4f& view_projection;
  int width = 0, height = 0;
  const ShadowProjection* shadow = nullptr;
  int shadow_map_size = 0;
};

/// The rectangles a frame clears and redraws.
struct FrameChanges {
  std::vector<rects::PixelRect> screen;  ///< framebuffer pixels
  std::vector<rects::PixelRect> texels;  ///< shadow-map texels
  std::vector<Eigen::AlignedBox3f> chunk_scratch;
};

/// The pixels whose shadow lookup can read a texel in `out.texels`: every drawable's box clipped
/// to the prism that the texels (plus two: the 2 x 2 lookup and rounding) sweep along the light;
/// added to `out.screen`. The rod's chunk boxes are `rod_chunks` (when `draw_rod`).
inline void add_shadow_readers(const Drawables& d, const DrawTarget& t, const FrameState& frame, bool draw_rod,
                               const std::vector<Eigen::AlignedBox3f>& rod_chunks, FrameChanges& out) {
  if (!t.shadow) return;
  const ShadowProjection& shadow = *t.shadow;
  const Eigen::Vector2f texel = (shadow.window_max - shadow.window_min).cwiseQuotient(Eigen::Vector2f(shadow.window_x, shadow.window_y));
  for (const rects::PixelRect& r : out.texels) {
    const Eigen::Vector2f lo = shadow.window_min + Eigen::Vector2f(r.x0 - 2.0f, r.y0 - 2.0f).cwiseProduct(texel);
    const Eigen::Vector2f hi = shadow.window_min + Eigen::Vector2f(r.x1 + 2.0f, r.y1 + 2.0f).cwiseProduct(texel);
    auto receives = [&](const Eigen::AlignedBox3f& box) {
      const rects::PixelRect p = rects::prism_screen_rect(box, shadow.view, lo, hi, t.view_projection, t.width, t.height);
      if (!p.empty()) out.screen.push_back(p);
    };
    for (std::size_t i = 0; i < d.scene.instances.size(); ++i) {
      receives(rects::world_box(frame.instance_poses[i], d.mesh_bounds[static_cast<std::size_t>(d.scene.instances[i].mesh)]));
    }
    if (draw_rod) {
      for (const Eigen::AlignedBox3f& b : rod_chunks) receives(b);
    }
    if (frame.goal_pose) receives(rects::world_box(*frame.goal_pose, d.triad_bounds));
  }
}

/// Incremental drawing: adds to `out` the screen rectangles that changed since the drawn frame and
/// the shadow-map texels whose casters changed (merged, at most `max_texel_rects`), then the
/// pixels that read those texels; refreshes drawn.rod_chunks to this frame's tube. Every box is
/// taken where the thing was and where it is.
inline void collect_changes(const Drawables& d, const DrawTarget& t, DrawnFrame& drawn, const FrameState& frame, bool draw_rod, bool rod_changed,
                            std::size_t max_texel_rects, FrameChanges& out) {
  auto changed = [&](const Eigen::AlignedBox3f& box, bool casts_shadow) {
    out.screen.push_back(rects::screen_rect(box, t.view_projection, t.width, t.height));
    if (casts_shadow && t.shadow) out.texels.push_back(rects::shadow_texel_rect(box, *t.shadow, t.shadow_map_size));
  };
  for (std::size_t i = 0; i < d.scene.instances.size(); ++i) {
    const math::Pose<double>& before = drawn.poses[i];
    const math::Pose<double>& now = frame.instance_poses[i];
    if (before.rotation == now.rotation && before.translation == now.translation) continue;
    const Eigen::AlignedBox3f& body_box = d.mesh_bounds[static_cast<std::size_t>(d.scene.instances[i].mesh)];
    changed(rects::world_box(before, body_box), d.scene.instances[i].casts_shadow);
    changed(rects::world_box(now, body_box), d.scene.instances[i].casts_shadow);
  }
  if (rod_changed) {
    // The tube in chunks of rings: a chunk whose vertices changed is redrawn where it was and
    // where it is (the chunk boxes of the drawn frame are kept in drawn.rod_chunks).
    out.chunk_scratch.clear();
    if (draw_rod) rod_chunk_boxes(d.tube, d.scene.rod.sides, out.chunk_scratch);
    const bool same_layout = drawn.rod && draw_rod && d.tube.positions.size() == drawn.rod_positions.size();
    const std::size_t chunks = std::max(out.chunk_scratch.size(), drawn.rod_chunks.size());
    for (std::size_t c = 0; c < chunks; ++c) {
      const bool before = c < drawn.rod_chunks.size(), now = c < out.chunk_scratch.size();
      if (same_layout && drawn.same_chunk(d.tube, d.scene.rod.sides, c)) continue;
      if (before) changed(drawn.rod_chunks[c], true);
      if (now) changed(out.chunk_scratch[c], true);
    }
    std::swap(drawn.rod_chunks, out.chunk_scratch);
  }
  const bool goal_same = frame.goal_pose.has_value() == drawn.goal.has_value() &&
                         (!frame.goal_pose || (frame.goal_pose->rotation == drawn.goal->rotation && frame.goal_pose->translation == drawn.goal->translation));
  if (!goal_same) {
    if (drawn.goal) changed(rects::world_box(*drawn.goal, d.triad_bounds), false);
    if (frame.goal_pose) changed(rects::world_box(*frame.goal_pose, d.triad_bounds), false);
  }
  rects::merge_rects(out.texels, max_texel_rects);
  add_shadow_readers(d, t, frame, draw_rod, drawn.rod_chunks, out);
}

}  // namespace manisoft::render::detail_gl
