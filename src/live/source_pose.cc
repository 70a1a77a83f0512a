#include "duet/live/source_pose.h"

#include <cmath>

#include "duet/motion/head_hands.h"

namespace duet {

PoseSource::PoseSource(SourceSkeleton skeleton, const PoseSourceOptions& options, std::string name)
    : skeleton_(std::move(skeleton)),
      name_(std::move(name)),
      queue_(skeleton_.joint_count(), options.queue_frames),
      device_offsets_(options.device_offsets) {}

bool PoseSource::reject(const char* why, std::string& reason) noexcept {
  ++stats_.rejected;
  try {
    reason = why;
  } catch (...) {  // out of memory for a short message: the count still says what happened
  }
  return false;
}

void PoseSource::commit(SourceFrame& slot, double time_s, SteadyClock::time_point arrival) noexcept {
  if (!have_epoch_) {
    have_epoch_ = true;
    epoch_ = arrival;
  }
  slot.time_s =
      std::isnan(time_s) ? std::chrono::duration<double>(arrival - epoch_).count() : time_s;
  slot.arrival = arrival;
  queue_.commit_push();
}

bool PoseSource::push(double time_s, const Vec3& root_position,
                      std::span<const double> rotations_wxyz, SteadyClock::time_point arrival,
                      std::string& reason) noexcept {
  const int joints = skeleton_.joint_count();
  if (is_head_hands_input(skeleton_.roles)) {
    return reject("pose: the headset source (--source xr) takes xr_pose messages", reason);
  }
  if (rotations_wxyz.size() != static_cast<std::size_t>(joints) * 4) {
    return reject("pose: 'rotations' must hold one [w, x, y, z] per joint of the source skeleton",
                  reason);
  }
  if (!root_position.allFinite() || root_position.norm() > 1000.0) {
    return reject("pose: 'root' must be 3 finite numbers within 1 km of the origin", reason);
  }
  if (!std::isnan(time_s) && !std::isfinite(time_s)) {
    return reject("pose: 'time_s' is not finite", reason);
  }

  SourceFrame& slot = queue_.begin_push();
  const Skeleton& skeleton = *skeleton_.skeleton;
  for (int j = 0; j < joints; ++j) {
    const std::size_t k = static_cast<std::size_t>(j) * 4;
    Quat q(rotations_wxyz[k], rotations_wxyz[k + 1], rotations_wxyz[k + 2], rotations_wxyz[k + 3]);
    const double norm = q.norm();
    if (!std::isfinite(norm) || !(norm > 0.5 && norm < 2.0)) {
      return reject("pose: every rotation must be a finite quaternion of about unit length",
                    reason);
    }
    q.coeffs() /= norm;
    slot.rotations_ls[static_cast<std::size_t>(j)] = q;
    slot.translations_ls[static_cast<std::size_t>(j)] =
        skeleton.joints[static_cast<std::size_t>(j)].offset;
  }
  slot.translations_ls[0] = root_position;
  commit(slot, time_s, arrival);
  return true;
}

bool PoseSource::push_points(double time_s, std::span<const Vec3> positions,
                             std::span<const double> orientations_wxyz,
                             SteadyClock::time_point arrival, std::string& reason) noexcept {
  if (!is_head_hands_input(skeleton_.roles) ||
      skeleton_.joint_count() != kHeadHandsJointCount) {
    return reject("xr_pose messages are for the headset source (duet serve --source xr)", reason);
  }
  if (positions.size() != 3 || orientations_wxyz.size() != 12) {
    return reject("xr_pose: needs a head, a left and a right hand", reason);
  }
  if (!std::isnan(time_s) && !std::isfinite(time_s)) {
    return reject("xr_pose: 'time_s' is not finite", reason);
  }
  for (const Vec3& p : positions) {
    if (!p.allFinite() || p.norm() > 1000.0) {
      return reject("xr_pose: every position must be finite and within 1 km of the origin",
                    reason);
    }
  }
  SourceFrame& slot = queue_.begin_push();
  slot.translations_ls[kPointsOrigin] = Vec3::Zero();
  slot.rotations_ls[kPointsOrigin] = Quat::Identity();
  for (std::size_t p = 0; p < 3; ++p) {
    Quat q(orientations_wxyz[4 * p], orientations_wxyz[4 * p + 1], orientations_wxyz[4 * p + 2],
           orientations_wxyz[4 * p + 3]);
    const double norm = q.norm();
    if (!std::isfinite(norm) || !(norm > 0.5 && norm < 2.0)) {
      return reject("xr_pose: every orientation must be a finite quaternion of about unit length",
                    reason);
    }
    q.coeffs() /= norm;
    slot.translations_ls[p + 1] = positions[p];
    slot.rotations_ls[p + 1] = q;
  }
  device_points_to_joints(device_offsets_, slot.translations_ls, slot.rotations_ls);
  commit(slot, time_s, arrival);
  return true;
}

bool PoseSource::poll(SteadyClock::time_point /*now*/, SourceFrame& out) noexcept {
  if (!queue_.pop(out)) return false;
  ++stats_.frames;
  return true;
}

SourceStats PoseSource::stats() const noexcept {
  SourceStats s = stats_;
  s.dropped = queue_.dropped();
  return s;
}

}  // namespace duet
