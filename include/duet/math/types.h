// Basic math types used across Duet. Eigen underneath; double precision for motion data.
// Conventions: Y is up; lengths in metres; times in seconds; angles in radians unless a name says
// degrees. Suffixes name the space: _ls (local to the parent joint), _ws (world).
#pragma once

#include <Eigen/Geometry>
#include <cmath>

namespace duet {

using Vec3 = Eigen::Vector3d;
using Quat = Eigen::Quaterniond;

// A rigid transform: first rotate, then translate.
struct Transform {
  Quat rotation = Quat::Identity();
  Vec3 translation = Vec3::Zero();

  Vec3 apply(const Vec3& point) const { return rotation * point + translation; }
  Transform operator*(const Transform& child) const {
    return {rotation * child.rotation, rotation * child.translation + translation};
  }
  Transform inverse() const {
    const Quat inv = rotation.conjugate();
    return {inv, inv * -translation};
  }
};

// Distance on the floor (x and z; Y is up).
inline double horizontal_distance(const Vec3& a, const Vec3& b) {
  return std::hypot(a.x() - b.x(), a.z() - b.z());
}

}  // namespace duet
