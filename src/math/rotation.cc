#include "duet/math/rotation.h"

#include <algorithm>
#include <cctype>
#include <cmath>

namespace duet {

bool parse_euler_order(std::string_view text, EulerOrder& order) {
  if (text.size() != 3) return false;
  bool seen[3] = {false, false, false};
  for (std::size_t k = 0; k < 3; ++k) {
    const char c = static_cast<char>(std::toupper(static_cast<unsigned char>(text[k])));
    if (c < 'X' || c > 'Z') return false;
    const int axis = c - 'X';
    if (seen[axis]) return false;
    seen[axis] = true;
    order[k] = static_cast<Axis>(axis);
  }
  return true;
}

char axis_name(Axis axis) { return static_cast<char>('X' + static_cast<int>(axis)); }

static Vec3 unit_axis(Axis axis) { return Vec3::Unit(static_cast<int>(axis)); }

Quat quat_from_euler(const Vec3& angles_rad, const EulerOrder& order) {
  Quat q = Quat::Identity();
  for (int k = 0; k < 3; ++k) {
    q = q * Quat(Eigen::AngleAxisd(angles_rad[k], unit_axis(order[k])));
  }
  return q.normalized();
}

Vec3 euler_from_quat(const Quat& q, const EulerOrder& order) {
  // Eigen's eulerAngles(a0, a1, a2) returns intrinsic angles for R = R_a0 * R_a1 * R_a2 with the
  // first angle in [0, pi]; re-solve to keep the middle angle in [-pi/2, pi/2] for nicer files.
  const Eigen::Matrix3d m = q.normalized().toRotationMatrix();
  const int i = static_cast<int>(order[0]);
  const int j = static_cast<int>(order[1]);
  const int k = static_cast<int>(order[2]);
  // Sign of the permutation (i, j, k): +1 for cyclic XYZ, YZX, ZXY.
  const double parity = ((j - i + 3) % 3 == 1) ? 1.0 : -1.0;
  const double sin_b = std::clamp(parity * m(i, k), -1.0, 1.0);
  // atan2 rather than asin: asin loses half the digits near +/-90 degrees.
  const double cos_b = std::hypot(m(i, i), m(i, j));
  const double b = std::atan2(sin_b, cos_b);
  double a = 0.0;
  double c = 0.0;
  if (cos_b > 1e-12) {
    a = std::atan2(-parity * m(j, k), m(k, k));
    // c from a and entries of size 1 (M. Day, "Extracting Euler angles from a rotation matrix"):
    // Ri(-a) * R = Rj(b) * Rk(c), whose row j holds sin c and cos c. Computing c on its own from
    // m(i, j) and m(i, i), which shrink with cos b, lost up to 3e-16 / cos b radians near gimbal
    // lock (3e-4 rad at 1e-12 from it); this way an error in a is compensated by c.
    const double ca = std::cos(a);
    const double sa = std::sin(a);
    c = std::atan2(parity * ca * m(j, i) + sa * m(k, i), ca * m(j, j) + parity * sa * m(k, j));
  } else {
    // Gimbal lock: only a + c (or a - c) is determined; put it all in a.
    a = std::atan2(parity * m(k, j), m(j, j));
    c = 0.0;
  }
  return {a, b, c};
}

Quat quat_from_axis_angle(const Vec3& axis_unit, double angle_rad) {
  return Quat(Eigen::AngleAxisd(angle_rad, axis_unit));
}

Vec3 log_map(const Quat& q_in) {
  Quat q = q_in.normalized();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();  // shortest arc: angle in [0, pi]
  const Vec3 v = q.vec();
  const double s = v.norm();
  if (s < 1e-12) return 2.0 * v;  // first-order: angle ~ 2 s
  const double angle = 2.0 * std::atan2(s, q.w());
  return v * (angle / s);
}

Quat exp_map(const Vec3& rotation_vector) {
  const double angle = rotation_vector.norm();
  if (angle < 1e-12) {
    Quat q(1.0, 0.5 * rotation_vector.x(), 0.5 * rotation_vector.y(), 0.5 * rotation_vector.z());
    return q.normalized();
  }
  return Quat(Eigen::AngleAxisd(angle, rotation_vector / angle));
}

double heading_yaw(const Quat& q) {
  Vec3 forward = q * Vec3::UnitZ();
  if (forward.x() * forward.x() + forward.z() * forward.z() < 1e-10) {
    const Vec3 side = q * Vec3::UnitX();
    return std::atan2(side.x(), side.z()) - kPi / 2.0;
  }
  return std::atan2(forward.x(), forward.z());
}

Quat yaw_rotation(double yaw_rad) { return Quat(Eigen::AngleAxisd(yaw_rad, Vec3::UnitY())); }

double wrap_angle(double angle_rad) {
  double a = std::fmod(angle_rad + kPi, 2.0 * kPi);
  if (a <= 0.0) a += 2.0 * kPi;
  return a - kPi;
}

}  // namespace duet
