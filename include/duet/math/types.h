// Basic math types used across Duet. Eigen underneath; double precision for motion data.
// Conventions: Y is up; lengths in metres; times in seconds; angles in radians unless a name says
// degrees. Suffixes name the space: _ls (local to the parent joint), _ws (world).
#pragma once

#include <Eigen/Geometry>

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

}  // namespace duet
