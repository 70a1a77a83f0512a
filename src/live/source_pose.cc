#include "duet/live/source_pose.h"

#include <cmath>

namespace duet {

PoseSource::PoseSource(SourceSkeleton skeleton, const PoseSourceOptions& options, std::string name)
    : skeleton_(std::move(skeleton)),
      name_(std::move(name)),
      queue_(skeleton_.joint_count(), options.queue_frames) {}

bool PoseSource::push(double time_s, const Vec3& root_position,
                      std::span<const double> rotations_wxyz, SteadyClock::time_point arrival,
                      std::string& reason) noexcept {
  const int joints = skeleton_.joint_count();
  auto reject = [&](const char* why) {
    ++stats_.rejected;
    try {
      reason = why;
    } catch (...) {  // out of memory for a short message: the count still says what happened
    }
    return false;
  };
  if (rotations_wxyz.size() != static_cast<std::size_t>(joints) * 4) {
    return reject("pose: 'rotations' must hold one [w, x, y, z] per joint of the source skeleton");
  }
  if (!root_position.allFinite() || root_position.norm() > 1000.0) {
    return reject("pose: 'root' must be 3 finite numbers within 1 km of the origin");
  }
  if (!std::isnan(time_s) && !std::isfinite(time_s)) return reject("pose: 'time_s' is not finite");

  SourceFrame& slot = queue_.begin_push();
  const Skeleton& skeleton = *skeleton_.skeleton;
  for (int j = 0; j < joints; ++j) {
    const std::size_t k = static_cast<std::size_t>(j) * 4;
    Quat q(rotations_wxyz[k], rotations_wxyz[k + 1], rotations_wxyz[k + 2], rotations_wxyz[k + 3]);
    const double norm = q.norm();
    if (!std::isfinite(norm) || !(norm > 0.5 && norm < 2.0)) {
      return reject("pose: every rotation must be a finite quaternion of about unit length");
    }
    q.coeffs() /= norm;
    slot.rotations_ls[static_cast<std::size_t>(j)] = q;
    slot.translations_ls[static_cast<std::size_t>(j)] =
        skeleton.joints[static_cast<std::size_t>(j)].offset;
  }
  slot.translations_ls[0] = root_position;
  if (!have_epoch_) {
    have_epoch_ = true;
    epoch_ = arrival;
  }
  slot.time_s =
      std::isnan(time_s) ? std::chrono::duration<double>(arrival - epoch_).count() : time_s;
  slot.arrival = arrival;
  queue_.commit_push();
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
