// The tool-down end-effector orientation every table-top motion uses: the rod's tip frame turned
// to point straight down (d1 = +x, d2 = -y, d3 = -z: the base frame bent down by 90 degrees),
// then yawed about world z. One definition for the reach targets, the reach map, the task
// environment's home and the expert's grasps.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "manisoft/math/se3.hpp"

namespace manisoft::control {

/// The tool-down rotation (end-effector frame -> world), yawed by `yaw` rad about world z.
inline Eigen::Matrix3d tool_down_rotation(double yaw) {
  Eigen::Matrix3d down;
  down << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * down;
}

/// The tool-down end-effector pose whose point `offset` (end-effector frame, e.g. a gripper's
/// grasp centre) lies at `point`.
inline math::Pose<double> tool_down_pose(const Eigen::Vector3d& point, double yaw, const Eigen::Vector3d& offset = Eigen::Vector3d::Zero()) {
  math::Pose<double> p;
  p.rotation = tool_down_rotation(yaw);
  p.translation = point - p.rotation * offset;
  return p;
}

}  // namespace manisoft::control
