#include "duet/live/source_frame.h"

#include <algorithm>
#include <cassert>

namespace duet {

void SourceFrame::resize(int joint_count) {
  translations_ls.assign(static_cast<std::size_t>(joint_count), Vec3::Zero());
  rotations_ls.assign(static_cast<std::size_t>(joint_count), Quat::Identity());
}

FrameQueue::FrameQueue(int joint_count, int capacity)
    : slots_(static_cast<std::size_t>(std::max(capacity, 1)) + 1) {
  // One slot more than the capacity, so begin_push() always has a free slot and a push that is
  // never committed cannot clobber a queued frame.
  for (SourceFrame& slot : slots_) slot.resize(joint_count);
}

SourceFrame& FrameQueue::begin_push() noexcept {
  const int n = static_cast<int>(slots_.size());
  return slots_[static_cast<std::size_t>((head_ + size_) % n)];
}

void FrameQueue::commit_push() noexcept {
  const int n = static_cast<int>(slots_.size());
  if (size_ == capacity()) {
    head_ = (head_ + 1) % n;  // the oldest frame makes room
    ++dropped_;
  } else {
    ++size_;
  }
}

bool FrameQueue::pop(SourceFrame& out) noexcept {
  if (size_ == 0) return false;
  const SourceFrame& slot = slots_[static_cast<std::size_t>(head_)];
  assert(out.translations_ls.size() == slot.translations_ls.size());
  out.time_s = slot.time_s;
  out.arrival = slot.arrival;
  const std::size_t n = std::min(out.translations_ls.size(), slot.translations_ls.size());
  std::copy_n(slot.translations_ls.begin(), n, out.translations_ls.begin());
  std::copy_n(slot.rotations_ls.begin(), n, out.rotations_ls.begin());
  head_ = (head_ + 1) % static_cast<int>(slots_.size());
  --size_;
  return true;
}

}  // namespace duet
