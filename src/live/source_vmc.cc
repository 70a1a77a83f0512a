#include "duet/live/source_vmc.h"

#include <cmath>

#include "duet/live/vmc_humanoid.h"

namespace duet {

namespace {

constexpr double kMaxPositionM = 1000.0;

bool finite(const Vec3& v) { return v.allFinite(); }

}  // namespace

const char* vmc_reject_name(VmcReject reason) {
  switch (reason) {
    case VmcReject::kNone:
      return "none";
    case VmcReject::kMalformed:
      return "not a valid OSC packet";
    case VmcReject::kForeign:
      return "not a VMC address";
    case VmcReject::kBadArguments:
      return "wrong arguments for a VMC message";
    case VmcReject::kNonFinite:
      return "a number is not finite or out of range";
    case VmcReject::kBadRotation:
      return "a rotation is not a unit quaternion";
  }
  return "unknown";
}

VmcSource::VmcSource(const VmcStreamOptions& options, std::string name, double frame_rate)
    : skeleton_(vmc_humanoid(frame_rate)),
      name_(std::move(name)),
      queue_(skeleton_.joint_count(), options.queue_frames) {
  current_.resize(skeleton_.joint_count());
  const Skeleton& s = *skeleton_.skeleton;
  for (int j = 0; j < s.joint_count(); ++j) {
    current_.translations_ls[static_cast<std::size_t>(j)] =
        s.joints[static_cast<std::size_t>(j)].offset;
    current_.rotations_ls[static_cast<std::size_t>(j)] = Quat::Identity();
  }
  hips_position_ = s.joints[0].offset;
}

bool VmcSource::check(const Vec3& position, const Quat& rotation, Quat& unit) noexcept {
  if (!finite(position) || !rotation.coeffs().allFinite() || position.norm() > kMaxPositionM) {
    reject(VmcReject::kNonFinite);
    return false;
  }
  const double norm = rotation.norm();
  if (!(norm > 0.5 && norm < 2.0)) {
    reject(VmcReject::kBadRotation);
    return false;
  }
  unit = Quat(rotation.coeffs() / norm);
  return true;
}

void VmcSource::root(const Vec3& position, const Quat& rotation) noexcept {
  Quat unit;
  if (!check(position, rotation, unit)) return;
  root_position_ = unity_to_duet(position);
  root_rotation_ = unity_to_duet(unit);
  dirty_ = true;
}

void VmcSource::bone(std::string_view name, const Vec3& position, const Quat& rotation) noexcept {
  Quat unit;
  if (!check(position, rotation, unit)) return;
  const int j = vmc_bone_index(name);
  if (j < 0) {
    ++ignored_;  // fingers, eyes, jaw: the humanoid has none
    return;
  }
  current_.rotations_ls[static_cast<std::size_t>(j)] = unity_to_duet(unit);
  if (j == 0) hips_position_ = unity_to_duet(position);
  dirty_ = true;
}

void VmcSource::frame_marker(SteadyClock::time_point arrival) noexcept {
  seen_marker_ = true;
  if (dirty_) emit(arrival);
}

void VmcSource::end_packet(SteadyClock::time_point arrival) noexcept {
  if (dirty_ && !seen_marker_) emit(arrival);
}

void VmcSource::reject(VmcReject reason) noexcept {
  ++stats_.rejected;
  last_rejection_ = reason;
}

void VmcSource::emit(SteadyClock::time_point arrival) noexcept {
  dirty_ = false;
  if (!have_epoch_) {
    have_epoch_ = true;
    epoch_ = arrival;
  }
  SourceFrame& slot = queue_.begin_push();
  std::copy(current_.translations_ls.begin(), current_.translations_ls.end(),
            slot.translations_ls.begin());
  std::copy(current_.rotations_ls.begin(), current_.rotations_ls.end(), slot.rotations_ls.begin());
  // The hips in the world: the avatar's root transform, then the hips relative to it.
  slot.translations_ls[0] = root_position_ + root_rotation_ * hips_position_;
  slot.rotations_ls[0] = (root_rotation_ * current_.rotations_ls[0]).normalized();
  slot.time_s = std::chrono::duration<double>(arrival - epoch_).count();
  slot.arrival = arrival;
  queue_.commit_push();
}

bool VmcSource::poll(SteadyClock::time_point /*now*/, SourceFrame& out) noexcept {
  if (!queue_.pop(out)) return false;
  ++stats_.frames;
  return true;
}

SourceStats VmcSource::stats() const noexcept {
  SourceStats s = stats_;
  s.dropped = queue_.dropped();
  return s;
}

}  // namespace duet
