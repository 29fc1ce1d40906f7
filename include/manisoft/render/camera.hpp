// Render cameras: a pinhole camera given by position, look-at point, up vector, vertical field of
// view and resolution, and its calibration in the OpenCV convention (ManiSoft paper
// section 3.2: 514 x 514 images, 60 degree field of view).
//
// OpenCV convention: camera axes x right, y down, z forward (along the view direction); a world
// point X maps to camera coordinates X_c = R X + t and to the pixel (u, v) = (K X_c) / z_c, where
// (u, v) = (0, 0) is the centre of the top-left pixel. For a symmetric frustum of vertical field
// of view fov and H rows: f = (H / 2) / tan(fov / 2) (square pixels, fx = fy = f), principal point
// c = ((W - 1) / 2, (H - 1) / 2).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <numbers>

#include "manisoft/core/error.hpp"

namespace manisoft::render {

/// A pinhole camera as a user places it. Defaults: the paper's 514 x 514, 60 degree camera
/// mapped into the ManiSoft world frame (docs/rendering.md).
struct Camera {
  Eigen::Vector3d position{2.0, 0.0, 2.35};  ///< m, world frame
  Eigen::Vector3d look_at{0.4, 0.0, 0.95};   ///< m, world point at the image centre
  Eigen::Vector3d up{0.0, 0.0, 1.0};         ///< world direction that appears upward
  double fov_y_deg = 60.0;                   ///< vertical field of view, degrees, in (0, 180)
  int width = 514;                           ///< pixels
  int height = 514;                          ///< pixels
  double near_clip = 0.05;                   ///< m, nearest rendered distance
  double far_clip = 20.0;                    ///< m, farthest rendered distance
};

/// A camera's calibration in the OpenCV convention (see the header comment).
struct CameraModel {
  int width = 0;
  int height = 0;
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();  ///< intrinsics
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  ///< world -> camera rotation
  Eigen::Vector3d t = Eigen::Vector3d::Zero();      ///< world -> camera translation, m
  double near_clip = 0.05;
  double far_clip = 20.0;

  /// Camera-frame coordinates of a world point: R X + t (z = depth along the view direction).
  Eigen::Vector3d to_camera(const Eigen::Vector3d& world) const { return R * world + t; }

  /// Pixel coordinates (u right, v down; integers at pixel centres) of a world point in front of
  /// the camera. Refuses a point at or behind the camera plane.
  Eigen::Vector2d project(const Eigen::Vector3d& world) const {
    const Eigen::Vector3d c = to_camera(world);
    if (!(c.z() > 0)) detail::fail("CameraModel::project: point depth z = ", c.z(), " m must be > 0 (point behind the camera)");
    const Eigen::Vector3d p = K * c;
    return {p.x() / p.z(), p.y() / p.z()};
  }

  /// The camera centre in world coordinates: -R^T t.
  Eigen::Vector3d position() const { return -(R.transpose() * t); }
};

/// Checks a camera and throws manisoft::Error naming the bad value and its limit.
inline void validate(const Camera& camera) {
  if (camera.width <= 0 || camera.height <= 0) {
    detail::fail("Camera size ", camera.width, " x ", camera.height, " is invalid: width and height must be >= 1 pixel");
  }
  if (camera.width > 16384 || camera.height > 16384) {
    detail::fail("Camera size ", camera.width, " x ", camera.height, " is invalid: at most 16384 pixels a side");
  }
  if (!std::isfinite(camera.fov_y_deg) || !(camera.fov_y_deg > 0.0) || !(camera.fov_y_deg < 180.0)) {
    detail::fail("Camera fov_y_deg = ", camera.fov_y_deg, " is invalid: it must lie in (0, 180) degrees");
  }
  if (!camera.position.allFinite() || !camera.look_at.allFinite() || !camera.up.allFinite()) {
    detail::fail("Camera position, look_at and up must be finite");
  }
  const Eigen::Vector3d view = camera.look_at - camera.position;
  if (!(view.norm() > 1e-9)) {
    detail::fail("Camera look_at = (", camera.look_at.transpose(), ") equals position: distance ", view.norm(),
                 " m must be > 1e-9 m");
  }
  if (!(camera.up.norm() > 1e-12)) detail::fail("Camera up vector has length ", camera.up.norm(), ": it must be non-zero");
  const double sine = view.normalized().cross(camera.up.normalized()).norm();
  if (!(sine > 1e-6)) {
    detail::fail("Camera up = (", camera.up.transpose(), ") is parallel to the view direction (", view.normalized().transpose(),
                 "): sine of the angle between them ", sine, " must be > 1e-6");
  }
  if (!(camera.near_clip > 0.0) || !(camera.far_clip > camera.near_clip) || !std::isfinite(camera.far_clip)) {
    detail::fail("Camera clip range [", camera.near_clip, ", ", camera.far_clip, "] m is invalid: need 0 < near < far < inf");
  }
}

/// The OpenCV calibration of a camera (validates it first).
inline CameraModel camera_model(const Camera& camera) {
  validate(camera);
  CameraModel m;
  m.width = camera.width;
  m.height = camera.height;
  m.near_clip = camera.near_clip;
  m.far_clip = camera.far_clip;
  const Eigen::Vector3d z = (camera.look_at - camera.position).normalized();  // forward
  const Eigen::Vector3d x = z.cross(camera.up).normalized();                 // right = forward x up
  const Eigen::Vector3d y = z.cross(x);                                      // down
  m.R.row(0) = x.transpose();
  m.R.row(1) = y.transpose();
  m.R.row(2) = z.transpose();
  m.t = -(m.R * camera.position);
  const double f = 0.5 * camera.height / std::tan(0.5 * camera.fov_y_deg * std::numbers::pi / 180.0);
  m.K << f, 0, 0.5 * (camera.width - 1), 0, f, 0.5 * (camera.height - 1), 0, 0, 1;
  return m;
}

}  // namespace manisoft::render
