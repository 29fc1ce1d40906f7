// Projection matrices of the OpenGL renderer (gl_renderer.hpp), in OpenGL's conventions (clip
// space, column vectors): look-at views, perspective and orthographic projections, the camera's
// view-projection that renders the OpenCV camera of camera.hpp upside down (so that
// glReadPixels returns rows top first), and the shadow map's projection: a spot light's frustum
// over its cone, or a directional light's orthographic projection restricted to a window of the
// map (the texels the shadow casters cover, at the whole map's texel size). Pure functions, no GL.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <vector>

#include "manisoft/math/se3.hpp"
#include "manisoft/render/camera.hpp"
#include "manisoft/render/scene.hpp"

namespace manisoft::render::detail_gl {

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

/// World to clip space of a camera (`model`: its calibration, camera_model(camera)). The OpenCV
/// camera (y down, z forward) turned into GL's eye frame (y up, z back), then the image turned
/// upside down (clip y negated) so that GL's bottom-up rows come back top row first: the mirror
/// turns counter-clockwise front faces clockwise. Pixel (u, v) of the OpenCV camera is window
/// position (u + 0.5, v + 0.5).
inline Eigen::Matrix4f camera_view_projection(const Camera& camera, const CameraModel& model) {
  Eigen::Matrix4d cv_to_gl = Eigen::Matrix4d::Identity();
  cv_to_gl(1, 1) = -1;
  cv_to_gl(2, 2) = -1;
  Eigen::Matrix4d flip_rows = Eigen::Matrix4d::Identity();
  flip_rows(1, 1) = -1;
  Eigen::Matrix4d world_to_camera = Eigen::Matrix4d::Identity();
  world_to_camera.topLeftCorner<3, 3>() = model.R;
  world_to_camera.topRightCorner<3, 1>() = model.t;
  return (flip_rows *
          perspective(camera.fov_y_deg * std::numbers::pi / 180.0, static_cast<double>(camera.width) / camera.height, camera.near_clip,
                      camera.far_clip) *
          cv_to_gl * world_to_camera)
      .cast<float>();
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

/// A spot light's shadow projection: a perspective frustum over its cone, the whole map of `size`
/// texels a side.
inline ShadowProjection spot_shadow_projection(const Lighting& l, int size) {
  const Eigen::Vector3d dir = l.direction.normalized();
  ShadowProjection out;
  out.bias = 1.0f / static_cast<float>(size);
  out.view_projection = perspective(2.0 * l.spot_cone_deg * std::numbers::pi / 180.0, 1.0, 0.1, 20.0).cast<float>() *
                        look_at(l.position, l.position + dir, Eigen::Vector3d::UnitZ());
  out.window_x = out.window_y = size;
  return out;
}

/// A directional light's view: from 2 r before the shadow sphere's centre (radius r), along the
/// light.
inline Eigen::Matrix4f directional_light_view(const Lighting& l) {
  const Eigen::Vector3d dir = l.direction.normalized();
  const double r = l.shadow_radius;
  const Eigen::Vector3d eye = l.shadow_center - dir * (2.0 * r);
  return look_at(eye, l.shadow_center, Eigen::Vector3d::UnitZ());
}

/// The shadow casters' extent in a light's view `view` (x, y, metres): the corners of each casting
/// instance's body-frame box (`mesh_bounds`, one per mesh) moved by its pose, and the vertices of
/// `tube` (the rod's, null when it is not drawn).
inline Eigen::AlignedBox2f casters_extent(const SceneDescription& scene, const std::vector<Eigen::AlignedBox3f>& mesh_bounds,
                                          const std::vector<math::Pose<double>>& poses, const Mesh* tube, const Eigen::Matrix4f& view) {
  Eigen::AlignedBox2f extent;
  for (std::size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& inst = scene.instances[i];
    if (!inst.casts_shadow) continue;
    const Eigen::AlignedBox3f& box = mesh_bounds[static_cast<std::size_t>(inst.mesh)];
    if (box.isEmpty()) continue;
    const Eigen::Matrix4f to_light = view * poses[i].matrix().cast<float>();
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3f corner = box.corner(static_cast<Eigen::AlignedBox3f::CornerType>(c));
      extent.extend((to_light.topLeftCorner<2, 3>() * corner + to_light.topRightCorner<2, 1>()).eval());
    }
  }
  if (tube) {
    for (const Eigen::Vector3f& p : tube->positions) extent.extend((view.topLeftCorner<2, 3>() * p + view.topRightCorner<2, 1>()).eval());
  }
  return extent;
}

/// A directional light's shadow projection: an orthographic projection whose texels are those of
/// the whole map of `size` texels spanning the shadow sphere (side 2 r), restricted to the texels
/// that cover `extent` (the casters' extent in the light's view `view`, x and y in metres; empty:
/// one texel) plus one texel a side: the shadow map's contents there are those of the whole map.
inline ShadowProjection directional_shadow_projection(const Lighting& l, const Eigen::Matrix4f& view, const Eigen::AlignedBox2f& extent, int size) {
  const double r = l.shadow_radius;
  ShadowProjection out;
  out.bias = 1.0f / static_cast<float>(size);
  // Whole-map texel k spans [-r + k tau, -r + (k + 1) tau]; the window is texels [k0, k1).
  const double tau = 2.0 * r / size;
  std::array<int, 2> k0{0, 0}, k1{1, 1};
  if (!extent.isEmpty()) {
    for (int a = 0; a < 2; ++a) {
      k0[a] = std::clamp(static_cast<int>(std::floor((extent.min()[a] + r) / tau)) - 1, 0, size - 1);
      k1[a] = std::clamp(static_cast<int>(std::ceil((extent.max()[a] + r) / tau)) + 1, k0[a] + 1, size);
    }
  }
  Eigen::Matrix4d projection = orthographic(r, 0.5 * r, 3.5 * r);
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

}  // namespace manisoft::render::detail_gl
