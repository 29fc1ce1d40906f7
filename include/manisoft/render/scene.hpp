// The renderer's input: a plain snapshot of shapes and poses, never the physics objects
// (ManiSoft paper, section 3.2: the policy's image V_t, and the randomized setting's
// textures and lighting). A SceneDescription is given once (meshes, materials with procedural
// textures, instances with object ids, lights, cameras); a FrameState per frame (instance poses,
// the rod's centreline and directors, the optional goal marker pose).
//
// Rod layout as in PyElastica: nodes (n + 1) x 3 in the lab frame; directors n x 9, row k is
// Q_k row-major, row i of Q_k is director d_{i+1} (Q_k maps lab to material coordinates).
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "manisoft/core/error.hpp"
#include "manisoft/math/se3.hpp"
#include "manisoft/render/camera.hpp"

namespace manisoft::render {

/// Triangle mesh in its own (body) frame: per-vertex positions, unit normals and texture
/// coordinates; triangles index the vertices, counter-clockwise seen from outside.
struct Mesh {
  std::vector<Eigen::Vector3f> positions;
  std::vector<Eigen::Vector3f> normals;
  std::vector<Eigen::Vector2f> uvs;
  std::vector<std::uint32_t> indices;  ///< 3 per triangle

  std::size_t triangle_count() const { return indices.size() / 3; }
};

/// Procedural textures evaluated per pixel from the body-frame position (solid textures: no
/// seams, no UV unwrapping needed).
enum class TextureKind : int { none = 0, wood = 1, marble = 2, fabric = 3, checker = 4, noise = 5 };

/// Surface appearance: base colour (linear RGB in [0, 1]) optionally modulated by a procedural
/// texture mixing base_color and secondary_color.
struct Material {
  Eigen::Vector3f base_color{0.7f, 0.7f, 0.7f};
  TextureKind texture = TextureKind::none;
  Eigen::Vector3f secondary_color{0.3f, 0.3f, 0.3f};
  float texture_scale = 10.0f;    ///< pattern frequency, 1/m (checker: squares per metre)
  float texture_strength = 1.0f;  ///< 0 = plain base colour, 1 = full pattern contrast
  float specular = 0.2f;          ///< Phong specular weight
  float shininess = 32.0f;        ///< Phong exponent
};

/// One drawn object: a mesh with a material, an object id for the mask and a name.
struct Instance {
  int mesh = 0;                ///< index into SceneDescription::meshes
  int material = 0;            ///< index into SceneDescription::materials
  std::uint16_t object_id = 1; ///< written to the mask; 0 is the background
  std::string name;
  bool casts_shadow = true;    ///< false for large receivers (floor): cheaper shadow pass
};

enum class LightKind : int { directional = 0, spot = 1 };

/// The main light (casts the shadows) plus ambient light.
struct Lighting {
  LightKind kind = LightKind::directional;
  Eigen::Vector3d direction{0.3, 0.45, -1.0};     ///< direction the light travels (world), any length
  Eigen::Vector3d position{1.2, -0.8, 2.6};       ///< spot light position, m
  double spot_cone_deg = 40.0;                    ///< spot half-angle, degrees, in (0, 80]
  Eigen::Vector3f color{1.0f, 1.0f, 1.0f};
  float intensity = 1.0f;
  Eigen::Vector3f ambient_color{1.0f, 1.0f, 1.0f};
  float ambient_intensity = 0.35f;
  /// Region the directional shadow map covers: a sphere (centre, radius in m).
  Eigen::Vector3d shadow_center{0.35, 0.0, 0.9};
  double shadow_radius = 1.1;
};

/// The rod drawn as a smooth tube.
struct RodAppearance {
  bool present = true;
  int material = 0;
  std::uint16_t object_id = 1;
  std::string name = "arm";
  int sides = 24;        ///< vertices around the tube
  int subdivisions = 4;  ///< tube rings per element (Catmull-Rom between nodes)
};

/// The ALN goal marker: an axis triad (x red, y green, z blue) drawn at FrameState::goal_pose.
struct GoalMarkerAppearance {
  std::uint16_t object_id = 1;
  std::string name = "goal";
  double axis_length = 0.08;  ///< m
  double axis_width = 0.008;  ///< m
};

/// Everything that stays fixed over an episode.
struct SceneDescription {
  std::vector<Mesh> meshes;
  std::vector<Material> materials;
  std::vector<Instance> instances;
  RodAppearance rod;
  GoalMarkerAppearance goal_marker;
  Lighting lighting;
  Eigen::Vector3f background_color{0.78f, 0.82f, 0.88f};
  std::vector<Camera> cameras{Camera{}};  ///< at least one; render() picks one by index
};

/// The rod's state for one frame (PyElastica layout, see the header comment).
struct RodShape {
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> nodes;      ///< (n + 1) x 3, m
  Eigen::Matrix<double, Eigen::Dynamic, 9, Eigen::RowMajor> directors;  ///< n x 9, or empty: frames from the centreline
  double radius = 0.05;                                                 ///< m
};

/// Everything that changes per frame.
struct FrameState {
  std::vector<math::Pose<double>> instance_poses;  ///< one per SceneDescription::instances
  RodShape rod;                                    ///< drawn when nodes has >= 2 rows and the scene's rod is present
  std::optional<math::Pose<double>> goal_pose;
};

/// Checks a scene (cameras, mesh indices and normals, instance meshes, materials and ids, the
/// rod's material, the lighting) and throws manisoft::Error naming the bad value and its limit.
inline void validate(const SceneDescription& scene) {
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

}  // namespace manisoft::render
