// An asset of the ManiSoft benchmark (paper section 3.3 and figure 4b: manipulable objects and
// obstacles): what it looks like (visual parts: triangle meshes with normals and texture
// coordinates, each with a material), how it collides (a geometry::Shape: primitives, convex
// pieces, or a compound of them for concave objects), its mass properties, its attributes (what
// language refers to) and its annotations (where the parallel gripper approaches, grasps and
// lifts it; how it rests; for containers and tableware where things go in).
//
// Frame convention (every asset): z up, the origin at the centre of the asset's footprint on its
// support plane in its canonical upright resting pose (so an asset placed at (x, y, table_top)
// with identity orientation rests on the table). Sizes in metres, masses in kilograms.
//
// Grasp frames are the gripper's attachment frame (interaction/gripper.hpp): origin at the centre
// of the palm's top face; +z points from the palm along the fingers (towards the object, so a
// tool-down grasp has z = -world z); +x is the closing axis. The object sits between the fingers,
// whose inner faces start palm_thickness below the frame origin.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <string>
#include <vector>

#include "manisoft/geometry/shapes.hpp"
#include "manisoft/math/se3.hpp"
#include "manisoft/render/scene.hpp"

namespace manisoft::assets {

enum class AssetKind { object, obstacle };

inline const char* to_string(AssetKind k) { return k == AssetKind::object ? "object" : "obstacle"; }

/// Coarse size, as instructions use it ("the small cup").
enum class SizeClass { small, medium, large };

inline const char* to_string(SizeClass s) {
  switch (s) {
    case SizeClass::small: return "small";
    case SizeClass::medium: return "medium";
    case SizeClass::large: return "large";
  }
  return "?";
}

/// The ManiSoft parallel gripper's dimensions: the one definition the grasp annotations
/// (catalog.hpp), the mesh importer's grasps and the simulated gripper
/// (interaction::ParallelGripperParameters) take.
struct GraspGripper {
  double palm_thickness = 0.05;    ///< m, attachment frame to the fingers' root
  double finger_length = 0.07;     ///< m
  double open_width = 0.10;        ///< m, between the inner finger faces
  double palm_clearance = 0.005;   ///< m, palm above the object's top (annotated grasps)
  double table_clearance = 0.01;   ///< m, fingertips above the support plane (annotated grasps)

  /// Gripper origin to the contact point along the approach axis: the fingers' middle.
  double grasp_depth() const { return palm_thickness + 0.5 * finger_length; }
};

/// A named visible part (body, cap, handle, label): mesh in the asset frame and its look.
struct VisualPart {
  std::string name;
  render::Mesh mesh;
  render::Material material;
  std::string color_name;  ///< "red", "dark blue": what an instruction may call it
  std::string material_name;  ///< "plastic", "glass", "ceramic", "metal", "wood", "cardboard", "fabric", "paper", "rubber"
};

/// What an instruction can refer to (the main part's colour and material name the asset).
struct Attributes {
  std::string color_name;                   ///< of the main part
  Eigen::Vector3f color_rgb{0.7f, 0.7f, 0.7f};  ///< linear RGB in [0, 1] of the main part
  std::string material_name;                ///< of the main part
  SizeClass size = SizeClass::medium;
  std::vector<std::string> parts;           ///< names of its visual parts ("body", "cap")
};

/// A candidate grasp for the parallel gripper (frames in the asset frame, see header comment):
/// move to `approach`, then straight to `grasp`, close, then to `lift`.
struct GraspAnnotation {
  math::Pose<double> approach;
  math::Pose<double> grasp;
  math::Pose<double> lift;
  double width = 0;  ///< m, the object's extent along the closing axis at the grasp (< open width)
};

/// A stable way to rest on a horizontal plane: orientation of the asset frame relative to a
/// frame on the plane (z up), and the height of the asset origin above the plane.
struct RestingPose {
  Eigen::Quaterniond orientation{Eigen::Quaterniond::Identity()};
  double height = 0;
  std::string name;  ///< "upright", "on its side"
};

/// Where things go in a container or onto tableware: `opening` is a frame at the centre of the
/// opening (rim plane), z up out of it; the inner volume is a vertical cylinder (radius > 0) or
/// box (half extents) whose top is the opening and whose bottom is `inner_depth` below it.
struct Receptacle {
  math::Pose<double> opening;
  double inner_radius = 0;                                ///< > 0: round
  Eigen::Vector2d inner_half_extents{0, 0};               ///< used when inner_radius == 0
  double inner_depth = 0;                                 ///< m from the opening down to the floor
  math::Pose<double> placement;                           ///< where a placed object's origin goes (on the floor)
};

/// One asset: geometry, physics, appearance, attributes, annotations.
struct Asset {
  std::string id;        ///< unique, "category/NN" (e.g. "bottle/03")
  std::string category;  ///< "bottle", "pill_bottle", ...
  AssetKind kind = AssetKind::object;
  std::vector<VisualPart> visual;           ///< in the asset frame
  geometry::Shape<double> collision{geometry::Box<double>{}};  ///< in the asset frame
  double mass = 0;                          ///< kg
  Eigen::Vector3d center_of_mass{Eigen::Vector3d::Zero()};     ///< asset frame
  Eigen::Matrix3d inertia{Eigen::Matrix3d::Zero()};            ///< kg m^2 about the COM, asset axes
  double friction = 0.6;
  double rolling_resistance = 2e-3;         ///< m (rigid::RigidBodyDesc::rolling_resistance; at 0.5 mm a bottle set down in a basket wobbled on its rim for over 0.5 s)
  Attributes attributes;
  std::vector<GraspAnnotation> grasps;      ///< empty for obstacles
  std::vector<RestingPose> resting_poses;   ///< the first is the canonical one
  std::vector<Receptacle> receptacles;      ///< containers and tableware
  Eigen::Vector3d bounding_half_extents{Eigen::Vector3d::Zero()};  ///< axis-aligned, about bounding_center
  Eigen::Vector3d bounding_center{Eigen::Vector3d::Zero()};
  std::string source;  ///< "generated" or the imported file's path
};

}  // namespace manisoft::assets
