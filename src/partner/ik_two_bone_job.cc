#include "duet/partner/ik_two_bone_job.h"

#include <algorithm>
#include <cmath>

#include "duet/math/rotation.h"

namespace duet {
namespace {

bool finite(const Vec3& v) { return v.allFinite(); }
bool unit(const Quat& q) { return q.coeffs().allFinite() && std::abs(q.norm() - 1.0) < 1e-3; }

// A unit vector perpendicular to `v` (|v| > 0), preferring the direction of `hint`.
Vec3 perpendicular(const Vec3& v, const Vec3& hint) {
  const Vec3 u = v.normalized();
  for (const Vec3& candidate : {hint, Vec3(Vec3::UnitY()), Vec3(Vec3::UnitX())}) {
    const Vec3 p = candidate - u * u.dot(candidate);
    if (p.norm() > 1e-6 * std::max(candidate.norm(), 1e-300)) return p.normalized();
  }
  return Vec3::UnitZ();  // unreachable: UnitY and UnitX cannot both be parallel to u
}

// The shortest-arc rotation carrying the direction of `from` onto that of `to` (both non-zero).
// Opposite directions turn half a turn about an axis perpendicular to `from`, preferring
// `axis_hint`, so the result is well defined.
Quat shortest_arc(const Vec3& from, const Vec3& to, const Vec3& axis_hint) {
  const Vec3 f = from.normalized();
  const Vec3 g = to.normalized();
  const double c = f.dot(g);
  if (c < -1.0 + 1e-12) return Quat(Eigen::AngleAxisd(kPi, perpendicular(f, axis_hint)));
  const Vec3 axis = f.cross(g);
  return Quat(1.0 + c, axis.x(), axis.y(), axis.z()).normalized();
}

// The distance the chain reaches for a target at distance d (soft_reach above): d itself up to
// (1 - soft) of the length, then an exponential approach to the full length.
double soft_distance(double d, double length, double soft) {
  const double soft_length = std::clamp(soft, 0.0, 1.0) * length;
  const double hard = length - soft_length;
  if (soft_length <= 0.0 || d <= hard) return d;
  return hard + soft_length * (1.0 - std::exp(-(d - hard) / soft_length));
}

}  // namespace

std::string_view IkTwoBoneJob::validate() const noexcept {
  if (start_joint_ws == nullptr) return "start_joint_ws is null";
  if (mid_joint_ws == nullptr) return "mid_joint_ws is null";
  if (end_joint_ws == nullptr) return "end_joint_ws is null";
  if (start_rotation_ls == nullptr) return "start_rotation_ls is null";
  if (mid_rotation_ls == nullptr) return "mid_rotation_ls is null";
  if (start_rotation_ls_out == nullptr) return "start_rotation_ls_out is null";
  if (mid_rotation_ls_out == nullptr) return "mid_rotation_ls_out is null";
  if (!finite(target_ws)) return "target_ws is not finite (not set?)";
  if (!std::isfinite(weight)) return "weight is not finite";
  if (!std::isfinite(swivel_offset_rad)) return "swivel_offset_rad is not finite";
  if (!(soft_reach >= 0.0 && soft_reach <= 1.0)) return "soft_reach is not within [0, 1]";
  if (!finite(start_joint_ws->translation) || !unit(start_joint_ws->rotation)) {
    return "start_joint_ws is not a finite rigid transform with a unit rotation";
  }
  if (!finite(mid_joint_ws->translation) || !unit(mid_joint_ws->rotation)) {
    return "mid_joint_ws is not a finite rigid transform with a unit rotation";
  }
  if (!finite(end_joint_ws->translation)) return "end_joint_ws has a non-finite position";
  if (!unit(*start_rotation_ls)) return "start_rotation_ls is not a unit quaternion";
  if (!unit(*mid_rotation_ls)) return "mid_rotation_ls is not a unit quaternion";
  return {};
}

bool IkTwoBoneJob::run() const noexcept {
  if (!validate().empty()) return false;

  const Vec3 s = start_joint_ws->translation;
  const Vec3 m = mid_joint_ws->translation;
  const Vec3 e = end_joint_ws->translation;
  const Vec3 to_target = target_ws - s;
  const Vec3 a = m - s;  // upper arm
  const Vec3 b = e - m;  // forearm
  const double l1 = a.norm();
  const double l2 = b.norm();
  const double d = to_target.norm();
  // Lengths below this are treated as zero; relative to the chain so any unit works.
  const double eps = 1e-9 * std::max(l1 + l2, d) + 1e-300;

  Quat bend = Quat::Identity();   // world-space rotation of the mid joint about its position
  Quat swing = Quat::Identity();  // world-space rotation of the start joint about its position
  Vec3 hinge = Vec3::UnitZ();

  if (l1 > eps && l2 > eps) {
    // The hinge: normal of the plane of the chain. A straight (or folded) chain has none; then
    // bend towards the target, else about an axis perpendicular to the upper arm.
    const Vec3 n = a.cross(b);
    if (n.norm() > 1e-9 * l1 * l2) {
      hinge = n.normalized();
    } else {
      const Vec3 toward = a.cross(to_target);
      hinge = perpendicular(
          a, toward.norm() > 1e-9 * l1 * std::max(d, eps) ? toward : Vec3(a.cross(Vec3::UnitY())));
    }
    // Law of cosines for the interior angle at the elbow, with the distance clamped to what the
    // chain can reach.
    const double dc = std::clamp(soft_distance(d, l1 + l2, soft_reach), std::abs(l1 - l2), l1 + l2);
    const double cos_wanted =
        std::clamp((l1 * l1 + l2 * l2 - dc * dc) / (2.0 * l1 * l2), -1.0, 1.0);
    const double cos_current = std::clamp(-a.dot(b) / (l1 * l2), -1.0, 1.0);
    // Turning the forearm by +phi about a x b closes the interior angle by phi.
    const double phi = std::acos(cos_current) - std::acos(cos_wanted);
    bend = Quat(Eigen::AngleAxisd(phi, hinge));
    const Vec3 reach = a + bend * b;  // shoulder-to-wrist after the bend
    if (reach.norm() > eps && d > eps) swing = shortest_arc(reach, to_target, hinge);
  } else if (l1 > eps) {
    // Zero-length forearm: the wrist sits on the elbow; point the upper arm at the target.
    if (d > eps) swing = shortest_arc(a, to_target, a.cross(Vec3::UnitY()));
  } else if (l2 > eps) {
    // Zero-length upper arm: the elbow sits on the shoulder; point the forearm at the target.
    const Vec3 from_mid = target_ws - m;
    if (from_mid.norm() > eps) bend = shortest_arc(b, from_mid, b.cross(Vec3::UnitY()));
  }
  if (swivel_offset_rad != 0.0 && d > eps) {
    swing = Quat(Eigen::AngleAxisd(swivel_offset_rad, to_target / d)) * swing;
  }

  const double w = std::clamp(weight, 0.0, 1.0);
  if (w < 1.0) {
    bend = Quat::Identity().slerp(w, bend);
    swing = Quat::Identity().slerp(w, swing);
  }

  // World corrections to local ones. The start joint turns by `swing` in the world:
  //   new_start_ws = swing * start_ws  =>  new_start_ls = start_ls * (start_ws^-1 swing start_ws).
  // The mid joint is carried by swing (through its ancestors) and turns by `bend` before it:
  //   new_mid_ws = swing * bend * mid_ws  =>  new_mid_ls = mid_ls * (mid_ws^-1 bend mid_ws).
  const Quat start_ws = start_joint_ws->rotation.normalized();
  const Quat mid_ws = mid_joint_ws->rotation.normalized();
  const Quat start_ls = start_rotation_ls->normalized();
  const Quat mid_ls = mid_rotation_ls->normalized();
  const Vec3 end_final = s + swing * (a + bend * b);

  *start_rotation_ls_out = (start_ls * (start_ws.conjugate() * swing * start_ws)).normalized();
  *mid_rotation_ls_out = (mid_ls * (mid_ws.conjugate() * bend * mid_ws)).normalized();
  if (reached != nullptr) {
    *reached = w >= 1.0 && (end_final - target_ws).norm() <= 1e-6 * std::max(l1 + l2, eps);
  }
  if (end_position_ws != nullptr) *end_position_ws = end_final;
  return true;
}

}  // namespace duet
