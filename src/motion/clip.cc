#include "duet/motion/clip.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace duet {

FrameBracket bracket_frame(double frame, int frame_count) noexcept {
  assert(frame_count > 0);
  const int last = frame_count - 1;
  const double position = std::isfinite(frame) ? std::clamp(frame, 0.0, double(last)) : 0.0;
  const int first = static_cast<int>(std::floor(position));
  return {first, std::min(first + 1, last), position - first};
}

void Pose::resize(int joint_count) {
  translations_ls.resize(static_cast<std::size_t>(joint_count));
  rotations_ls.resize(static_cast<std::size_t>(joint_count));
}

Clip::Clip(std::shared_ptr<const Skeleton> skeleton, double frame_rate, int frame_count)
    : skeleton_(std::move(skeleton)), frame_rate_(frame_rate), frame_count_(frame_count) {
  assert(skeleton_ && frame_count >= 0);
  const int n = skeleton_->joint_count();
  translations_ls_.resize(static_cast<std::size_t>(frame_count) * static_cast<std::size_t>(n));
  rotations_ls_.assign(translations_ls_.size(), Quat::Identity());
  for (int f = 0; f < frame_count; ++f) {
    auto t = translations_ls(f);
    for (int j = 0; j < n; ++j) t[static_cast<std::size_t>(j)] = skeleton_->joints[static_cast<std::size_t>(j)].offset;
  }
}

static std::size_t frame_begin(int frame, int joint_count) {
  return static_cast<std::size_t>(frame) * static_cast<std::size_t>(joint_count);
}

std::span<Vec3> Clip::translations_ls(int frame) {
  assert(frame >= 0 && frame < frame_count_);
  return {translations_ls_.data() + frame_begin(frame, joint_count()),
          static_cast<std::size_t>(joint_count())};
}
std::span<const Vec3> Clip::translations_ls(int frame) const {
  assert(frame >= 0 && frame < frame_count_);
  return {translations_ls_.data() + frame_begin(frame, joint_count()),
          static_cast<std::size_t>(joint_count())};
}
std::span<Quat> Clip::rotations_ls(int frame) {
  assert(frame >= 0 && frame < frame_count_);
  return {rotations_ls_.data() + frame_begin(frame, joint_count()),
          static_cast<std::size_t>(joint_count())};
}
std::span<const Quat> Clip::rotations_ls(int frame) const {
  assert(frame >= 0 && frame < frame_count_);
  return {rotations_ls_.data() + frame_begin(frame, joint_count()),
          static_cast<std::size_t>(joint_count())};
}

void Clip::pose_at(int frame, Pose& pose) const {
  pose.resize(joint_count());
  std::ranges::copy(translations_ls(frame), pose.translations_ls.begin());
  std::ranges::copy(rotations_ls(frame), pose.rotations_ls.begin());
}

void Clip::sample(double time_s, Pose& pose) const {
  assert(frame_count_ > 0);
  const auto [f0, f1, w] = bracket_frame(time_s * frame_rate_, frame_count_);
  pose.resize(joint_count());
  const auto t0 = translations_ls(f0), t1 = translations_ls(f1);
  const auto r0 = rotations_ls(f0), r1 = rotations_ls(f1);
  for (std::size_t j = 0; j < t0.size(); ++j) {
    pose.translations_ls[j] = (1.0 - w) * t0[j] + w * t1[j];
    pose.rotations_ls[j] = r0[j].slerp(w, r1[j]);
  }
}

void Clip::scale_lengths(double factor) {
  auto scaled = std::make_shared<Skeleton>(*skeleton_);
  for (Joint& j : scaled->joints) j.offset *= factor;
  skeleton_ = std::move(scaled);
  for (Vec3& t : translations_ls_) t *= factor;
}

void Clip::keep_first_frames(int count) {
  assert(count >= 0);
  if (count >= frame_count_) return;
  frame_count_ = count;
  translations_ls_.resize(frame_begin(count, joint_count()));
  rotations_ls_.resize(translations_ls_.size());
}

}  // namespace duet
