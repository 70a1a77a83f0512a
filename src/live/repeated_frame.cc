#include "duet/live/repeated_frame.h"

#include <algorithm>
#include <utility>

namespace duet {

RepeatedFrameDetector::RepeatedFrameDetector(int joints, std::vector<int> tracked_points)
    : tracked_points_(std::move(tracked_points)) {
  const auto size = static_cast<std::size_t>(std::max(joints, 0));
  translations_.resize(size, Vec3::Zero());
  rotations_.resize(size, Quat::Identity());
  std::erase_if(tracked_points_,
                [&](int j) { return j < 0 || static_cast<std::size_t>(j) >= size; });
}

bool RepeatedFrameDetector::is_repeat(std::span<const Vec3> translations_ls,
                                      std::span<const Quat> rotations_ls) noexcept {
  if (translations_ls.size() != translations_.size() || rotations_ls.size() != rotations_.size()) {
    reset();
    return false;
  }
  // Bit for bit: a real sensor's own noise never gives the same pose twice.
  const bool same =
      has_previous_ &&
      std::equal(translations_ls.begin(), translations_ls.end(), translations_.begin(),
                 [](const Vec3& a, const Vec3& b) { return a == b; }) &&
      std::equal(rotations_ls.begin(), rotations_ls.end(), rotations_.begin(),
                 [](const Quat& a, const Quat& b) { return a.coeffs() == b.coeffs(); });
  const bool point_stalled = has_previous_ && std::ranges::any_of(tracked_points_, [&](int j) {
                               const auto i = static_cast<std::size_t>(j);
                               return translations_ls[i] == translations_[i] &&
                                      rotations_ls[i].coeffs() == rotations_[i].coeffs();
                             });
  if (!same) {
    std::copy(translations_ls.begin(), translations_ls.end(), translations_.begin());
    std::copy(rotations_ls.begin(), rotations_ls.end(), rotations_.begin());
  }
  has_previous_ = true;
  return same || point_stalled;
}

void RepeatedFrameDetector::reset() noexcept { has_previous_ = false; }

}  // namespace duet
