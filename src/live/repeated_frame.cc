#include "duet/live/repeated_frame.h"

#include <algorithm>

namespace duet {

RepeatedFrameDetector::RepeatedFrameDetector(int joints) {
  const auto size = static_cast<std::size_t>(std::max(joints, 0));
  translations_.resize(size, Vec3::Zero());
  rotations_.resize(size, Quat::Identity());
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
  if (!same) {
    std::copy(translations_ls.begin(), translations_ls.end(), translations_.begin());
    std::copy(rotations_ls.begin(), rotations_ls.end(), rotations_.begin());
  }
  has_previous_ = true;
  return same;
}

void RepeatedFrameDetector::reset() noexcept { has_previous_ = false; }

}  // namespace duet
