// The renderer interface: a Renderer takes a SceneDescription once and a FrameState per frame and
// returns a RenderOutput (RGB, depth, object-id mask and the camera's OpenCV calibration). Code
// that draws frames is written against the concept, so that a backend is one header defining a
// type that satisfies it. GlRenderer (gl_renderer.hpp) is the in-process one; the Blender adapter
// (blender_export.hpp) renders the same snapshots offline, in batches. Also: each object's world
// bounding box for a frame (what camera.json lists per id), and the gripper's part poses from its
// frame.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <string>

#include "manisoft/render/image.hpp"
#include "manisoft/render/scene.hpp"

namespace manisoft::render {

/// What every renderer backend provides: its options (R::Options, which say at least whether
/// depth and ids are read back), construction from them, set_scene() once, then per frame
/// render() or render_into() (the same image into a RenderOutput whose buffers are reused).
template <typename R>
concept Renderer = std::constructible_from<R, const typename R::Options&> &&
                   requires(R renderer, typename R::Options options, const SceneDescription& scene, const FrameState& frame, std::size_t camera,
                            RenderOutput& out) {
                     options.read_depth = false;
                     options.read_mask = false;
                     renderer.set_scene(scene);
                     { renderer.render(frame, camera) } -> std::same_as<RenderOutput>;
                     renderer.render_into(frame, out, camera);
                   };

/// A renderer that reads back colour only (no depth, no ids), its other options the defaults:
/// the image a policy sees.
template <Renderer R>
std::unique_ptr<R> make_colour_renderer() {
  typename R::Options options;
  options.read_depth = false;
  options.read_mask = false;
  return std::make_unique<R>(options);
}

/// An object's name and world axis-aligned bounding box in one frame.
struct ObjectBounds {
  std::string name;
  Eigen::Vector3d min = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d max = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());

  Eigen::Vector3d center() const { return 0.5 * (min + max); }
  void extend(const Eigen::Vector3d& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
};

/// World bounding boxes per object id (instances sharing an id are merged), the rod included
/// (nodes +- radius) and the goal marker when present.
inline std::map<std::uint16_t, ObjectBounds> object_bounds(const SceneDescription& scene, const FrameState& frame) {
  std::map<std::uint16_t, ObjectBounds> out;
  for (std::size_t i = 0; i < scene.instances.size() && i < frame.instance_poses.size(); ++i) {
    const Instance& inst = scene.instances[i];
    if (inst.mesh < 0 || static_cast<std::size_t>(inst.mesh) >= scene.meshes.size()) continue;
    ObjectBounds& b = out[inst.object_id];
    if (b.name.empty()) b.name = inst.name;
    for (const Eigen::Vector3f& p : scene.meshes[static_cast<std::size_t>(inst.mesh)].positions) b.extend(frame.instance_poses[i].act(p.cast<double>()));
  }
  if (scene.rod.present && frame.rod.nodes.rows() >= 2) {
    ObjectBounds& b = out[scene.rod.object_id];
    if (b.name.empty()) b.name = scene.rod.name;
    for (Eigen::Index k = 0; k < frame.rod.nodes.rows(); ++k) {
      b.extend(frame.rod.nodes.row(k).transpose() - Eigen::Vector3d::Constant(frame.rod.radius));
      b.extend(frame.rod.nodes.row(k).transpose() + Eigen::Vector3d::Constant(frame.rod.radius));
    }
  }
  if (frame.goal_pose) {
    ObjectBounds& b = out[scene.goal_marker.object_id];
    if (b.name.empty()) b.name = scene.goal_marker.name;
    const double l = scene.goal_marker.axis_length;
    b.extend(frame.goal_pose->translation);
    for (int a = 0; a < 3; ++a) b.extend(frame.goal_pose->act(l * Eigen::Vector3d::Unit(a)));
  }
  return out;
}

/// The parallel gripper's parts (same geometry as interaction/gripper.hpp's ParallelGripper defaults):
/// frame origin at the centre of the palm's top face, +z the approach axis (into the palm and on
/// along the fingers), +x the closing axis.
struct GripperGeometry {
  Eigen::Vector3d palm_half_extents{0.06, 0.05, 0.025};    ///< m
  Eigen::Vector3d finger_half_extents{0.005, 0.02, 0.035}; ///< m (x along the closing axis)
  double max_opening = 0.10;                               ///< m between the fingers' inner faces
};

/// Body-to-world poses of palm, left finger (-x) and right finger (+x) for a gripper frame and
/// finger opening (clamped to [0, max_opening]).
inline std::array<math::Pose<double>, 3> gripper_part_poses(const math::Pose<double>& gripper, double opening, const GripperGeometry& g = {}) {
  const double w = std::clamp(opening, 0.0, g.max_opening);
  const double palm_z = g.palm_half_extents.z();
  math::Pose<double> palm{Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, palm_z)};
  const double fx = 0.5 * w + g.finger_half_extents.x();
  const double fz = 2 * palm_z + g.finger_half_extents.z();
  math::Pose<double> left{Eigen::Matrix3d::Identity(), Eigen::Vector3d(-fx, 0, fz)};
  math::Pose<double> right{Eigen::Matrix3d::Identity(), Eigen::Vector3d(fx, 0, fz)};
  return {gripper * palm, gripper * left, gripper * right};
}

}  // namespace manisoft::render
