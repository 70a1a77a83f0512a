#include "duet/live/repeated_frame.h"

#include <algorithm>
#include <utility>

namespace duet {

RepeatedFrameDetector::RepeatedFrameDetector(int joints, std::vector<int> tracked_points)
    : tracked_points_(std::move(tracked_points)) {
  const auto size = static_cast<std::size_t>(std::max(joints, 0));
  translations_.resize(size, Vec3::Zero());
  rotations_.resize(size, Quat::Identity());
  for (int& j : tracked_points_) {
    if (j < 0 || static_cast<std::size_t>(j) >= size) j = -1;
  }
  point_repeated_.assign(tracked_points_.size(), false);
}

bool RepeatedFrameDetector::is_repeat(std::span<const Vec3> translations_ls,
                                      std::span<const Quat> rotations_ls) noexcept {
  if (translations_ls.size() != translations_.size() || rotations_ls.size() != rotations_.size()) {
    reset();
    return false;
  }
  whole_ = false;
  std::fill(point_repeated_.begin(), point_repeated_.end(), false);
  // Bit for bit: a real sensor's own noise never gives the same pose twice.
  const bool same =
      has_previous_ &&
      std::equal(translations_ls.begin(), translations_ls.end(), translations_.begin(),
                 [](const Vec3& a, const Vec3& b) { return a == b; }) &&
      std::equal(rotations_ls.begin(), rotations_ls.end(), rotations_.begin(),
                 [](const Quat& a, const Quat& b) { return a.coeffs() == b.coeffs(); });
  bool point_stalled = false;
  for (std::size_t p = 0; p < tracked_points_.size() && has_previous_; ++p) {
    if (tracked_points_[p] < 0) continue;
    const auto i = static_cast<std::size_t>(tracked_points_[p]);
    point_repeated_[p] = translations_ls[i] == translations_[i] &&
                         rotations_ls[i].coeffs() == rotations_[i].coeffs();
    point_stalled = point_stalled || point_repeated_[p];
  }
  whole_ = same;
  if (!same) {
    std::copy(translations_ls.begin(), translations_ls.end(), translations_.begin());
    std::copy(rotations_ls.begin(), rotations_ls.end(), rotations_.begin());
  }
  has_previous_ = true;
  return same || point_stalled;
}

void RepeatedFrameDetector::reset() noexcept {
  has_previous_ = false;
  whole_ = false;
  std::fill(point_repeated_.begin(), point_repeated_.end(), false);
}

}  // namespace duet
