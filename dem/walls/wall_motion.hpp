#pragma once
// Prescribed rigid motion of a wall: constant translation V and constant rotation
// w about a fixed axis (unit a through P). A point x0 of the wall (at t = 0) is at
//   x(t) = P + V t + R(t) (x0 - P),   R(t) = rotation by w t about a,
// and the wall's velocity at a point y is V + w a x (y - (P + V t)).
#include <Eigen/Geometry>

#include "dem/scene/scene.hpp"

namespace grainflow {

class WallPose {
 public:
  WallPose() = default;
  explicit WallPose(const WallMotion& m) : m_(m) {
    moving_ = m.velocity.squaredNorm() > 0 || m.angular_velocity != 0;
    move_to(0);
  }

  bool moving() const { return moving_; }

  void move_to(double t) {
    rotation_ = Eigen::AngleAxisd(m_.angular_velocity * t, m_.axis).toRotationMatrix();
    centre_ = m_.axis_point + m_.velocity * t;
  }

  Vec3 to_world(const Vec3& x0) const { return centre_ + rotation_ * (x0 - m_.axis_point); }
  Vec3 to_body(const Vec3& x) const {
    return m_.axis_point + rotation_.transpose() * (x - centre_);
  }
  Vec3 direction_to_world(const Vec3& d0) const { return rotation_ * d0; }
  Vec3 spin() const { return m_.angular_velocity * m_.axis; }  // angular velocity [rad/s]
  Vec3 velocity_at(const Vec3& y) const {
    return m_.velocity + m_.angular_velocity * m_.axis.cross(y - centre_);
  }

 private:
  WallMotion m_;
  bool moving_ = false;
  Eigen::Matrix3d rotation_ = Eigen::Matrix3d::Identity();
  Vec3 centre_ = Vec3::Zero();
};

}  // namespace grainflow
