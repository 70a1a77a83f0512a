// Rotation conversions: Euler angles at the file boundary, rotation vectors (log map) for
// features, heading (yaw about +Y) for placing bodies in a room.
#pragma once

#include <array>
#include <string_view>

#include "duet/math/types.h"

namespace duet {

enum class Axis : int { kX = 0, kY = 1, kZ = 2 };

// The order in which a file lists its rotation channels, e.g. "ZXY" for Zrotation Xrotation
// Yrotation. BVH composes intrinsically in listed order: R = R_first * R_second * R_third.
// ASF/AMC is the other way round (`dof rx ry rz` means R = Rz * Ry * Rx): reverse the order
// before calling quat_from_euler for ASF data.
using EulerOrder = std::array<Axis, 3>;

// Parses "XYZ", "zxy", ... Returns false if the string is not a permutation of X, Y, Z.
bool parse_euler_order(std::string_view text, EulerOrder& order);
char axis_name(Axis axis);

// angles_rad[k] is the angle about order[k].
Quat quat_from_euler(const Vec3& angles_rad, const EulerOrder& order);
// Inverse of quat_from_euler (angles of the middle axis in [-pi/2, pi/2]).
Vec3 euler_from_quat(const Quat& q, const EulerOrder& order);

Quat quat_from_axis_angle(const Vec3& axis_unit, double angle_rad);

// Log map: the rotation vector (axis * angle, angle in [0, pi]) of a unit quaternion. Continuous
// away from angle pi, unlike Euler angles. exp_map is its inverse.
Vec3 log_map(const Quat& q);
Quat exp_map(const Vec3& rotation_vector);

// Heading: the rotation about +Y that best matches q's facing. We take the yaw of the rotated +Z
// axis projected on the ground (falls back to +X when +Z points straight up or down).
double heading_yaw(const Quat& q);
Quat yaw_rotation(double yaw_rad);

// Wraps an angle to (-pi, pi].
double wrap_angle(double angle_rad);

constexpr double kPi = 3.14159265358979323846;
constexpr double deg_to_rad(double deg) { return deg * kPi / 180.0; }
constexpr double rad_to_deg(double rad) { return rad * 180.0 / kPi; }

}  // namespace duet
