// A picture of one asset (paper section 3.3 and figure 4b: the benchmark's objects and obstacles):
// its visual parts as a render snapshot (render::SceneDescription + FrameState, no OpenGL here)
// on a light ground slab, and a camera that frames the asset's bounding box from a 3/4 view
// (looking down from a given elevation at a given azimuth; the box's bounding sphere fills the
// vertical field of view with a margin). Used by asset_gallery's contact sheet.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <cstdint>

#include "manisoft/assets/asset.hpp"
#include "manisoft/core/error.hpp"
#include "manisoft/render/camera.hpp"
#include "manisoft/render/mesh_builders.hpp"
#include "manisoft/render/scene.hpp"

namespace manisoft::assets {

/// How an asset is looked at.
struct AssetViewOptions {
  double azimuth_deg = -55.0;   ///< camera direction about z from the asset's +x axis
  double elevation_deg = 28.0;  ///< above the horizontal
  double fov_y_deg = 30.0;
  double margin = 1.08;         ///< bounding sphere radius scale (> 1: a little space around)
  int width = 160, height = 160;
  bool ground = true;           ///< a light slab under the asset (catches its shadow)
};

/// The camera framing `asset` (in its own frame, resting pose identity) for `options`.
inline render::Camera frame_asset(const Asset& asset, const AssetViewOptions& options = {}) {
  if (!(options.margin >= 1.0) || !std::isfinite(options.margin))
    manisoft::detail::fail("AssetViewOptions margin = ", options.margin, " must be >= 1");
  if (!(options.elevation_deg > -90.0 && options.elevation_deg < 90.0))
    manisoft::detail::fail("AssetViewOptions elevation_deg = ", options.elevation_deg, " must lie in (-90, 90)");
  const double radius = asset.bounding_half_extents.norm();
  if (!(radius > 0) || !std::isfinite(radius))
    manisoft::detail::fail("frame_asset: asset ", asset.id, " has bounding half extents (", asset.bounding_half_extents.transpose(),
                           "): they must be finite and not all zero");
  const double pi = 3.14159265358979323846;
  const double az = options.azimuth_deg * pi / 180.0, el = options.elevation_deg * pi / 180.0;
  const Eigen::Vector3d dir(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
  // The sphere of radius R at distance d subtends half-angle asin(R / d): fit it to fov / 2
  // (of the narrower image side).
  const double half_fov_y = 0.5 * options.fov_y_deg * pi / 180.0;
  const double aspect = static_cast<double>(options.width) / options.height;
  const double half_fov = aspect >= 1.0 ? half_fov_y : std::atan(std::tan(half_fov_y) * aspect);
  const double distance = options.margin * radius / std::sin(half_fov);
  render::Camera cam;
  cam.look_at = asset.bounding_center;
  cam.position = asset.bounding_center + distance * dir;
  cam.up = Eigen::Vector3d::UnitZ();
  cam.fov_y_deg = options.fov_y_deg;
  cam.width = options.width;
  cam.height = options.height;
  cam.near_clip = 0.2 * distance;
  cam.far_clip = 4.0 * distance;
  render::validate(cam);
  return cam;
}

/// Render snapshot of `asset` (visual parts with their materials, all with `object_id`; the
/// ground slab, if any, with id object_id + 1) framed by frame_asset, lit from above and behind
/// the camera's right shoulder (shadows fall to the image's left).
inline void asset_scene(const Asset& asset, const AssetViewOptions& options, render::SceneDescription& scene,
                        render::FrameState& frame, std::uint16_t object_id = 1) {
  scene = render::SceneDescription{};
  frame = render::FrameState{};
  scene.rod.present = false;
  for (const auto& part : asset.visual) {
    scene.meshes.push_back(part.mesh);
    scene.materials.push_back(part.material);
    scene.instances.push_back(render::Instance{static_cast<int>(scene.meshes.size() - 1), static_cast<int>(scene.materials.size() - 1),
                                               object_id, asset.id, true});
    frame.instance_poses.emplace_back();
  }
  const double radius = asset.bounding_half_extents.norm();
  if (options.ground) {
    const double half = 3.0 * radius;
    scene.meshes.push_back(render::make_box(Eigen::Vector3d(half, half, 0.002)));
    render::Material g;
    g.base_color = Eigen::Vector3f(0.86f, 0.86f, 0.84f);
    g.specular = 0.05f;
    scene.materials.push_back(g);
    scene.instances.push_back(render::Instance{static_cast<int>(scene.meshes.size() - 1), static_cast<int>(scene.materials.size() - 1),
                                               static_cast<std::uint16_t>(object_id + 1), "ground", false});
    math::Pose<double> at;
    at.translation = Eigen::Vector3d(asset.bounding_center.x(), asset.bounding_center.y(),
                                     asset.bounding_center.z() - asset.bounding_half_extents.z() - 0.002);
    frame.instance_poses.push_back(at);
  }
  const render::Camera cam = frame_asset(asset, options);
  scene.cameras = {cam};
  // The light travels along the view, toward the image's left and down.
  const Eigen::Vector3d view = (cam.look_at - cam.position).normalized();
  const Eigen::Vector3d left = Eigen::Vector3d::UnitZ().cross(view).normalized();
  scene.lighting.kind = render::LightKind::directional;
  scene.lighting.direction = view + 0.6 * left - 1.2 * Eigen::Vector3d::UnitZ();
  scene.lighting.ambient_intensity = 0.45f;
  scene.lighting.shadow_center = asset.bounding_center;
  scene.lighting.shadow_radius = 2.0 * radius;
  scene.background_color = Eigen::Vector3f(0.97f, 0.97f, 0.98f);
}

}  // namespace manisoft::assets
