#include "duet/motion/skeleton.h"

#include <array>
#include <cmath>
#include <unordered_set>

namespace duet {

namespace {
constexpr std::array<std::string_view, 6> kChannelNames = {
    "Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation"};
}  // namespace

std::string_view channel_name(Channel channel) {
  return kChannelNames[static_cast<std::size_t>(channel)];
}

std::optional<Channel> parse_channel(std::string_view name) {
  for (std::size_t k = 0; k < kChannelNames.size(); ++k) {
    if (name == kChannelNames[k]) return static_cast<Channel>(k);
  }
  return std::nullopt;
}

bool Joint::has_position_channels() const {
  for (Channel c : channels) {
    if (is_position_channel(c)) return true;
  }
  return false;
}

EulerOrder Joint::rotation_order() const {
  EulerOrder order{Axis::kX, Axis::kY, Axis::kZ};
  int n = 0;
  for (Channel c : channels) {
    if (!is_position_channel(c) && n < 3) {
      order[static_cast<std::size_t>(n++)] = static_cast<Axis>(static_cast<int>(c) - 3);
    }
  }
  return order;
}

std::string Skeleton::validate() const {
  if (joints.empty()) return "skeleton has no joints";
  if (joints[0].parent != -1) return "joint 0 must be the root (parent -1)";
  std::unordered_set<std::string> names;
  for (int i = 0; i < joint_count(); ++i) {
    const Joint& j = joints[static_cast<std::size_t>(i)];
    if (i > 0 && (j.parent < 0 || j.parent >= i)) {
      return "joint '" + j.name + "' must come after its parent";
    }
    if (!names.insert(j.name).second) return "joint name '" + j.name + "' is used twice";
    if (!j.offset.allFinite()) return "joint '" + j.name + "' has a non-finite offset";
    if (j.end_site && !j.channels.empty()) return "End Site '" + j.name + "' has channels";
  }
  return {};
}

int Skeleton::find(std::string_view name) const {
  for (int i = 0; i < joint_count(); ++i) {
    if (joints[static_cast<std::size_t>(i)].name == name) return i;
  }
  return -1;
}

int Skeleton::channel_count() const {
  int n = 0;
  for (const Joint& j : joints) n += static_cast<int>(j.channels.size());
  return n;
}

int Skeleton::animated_joint_count() const {
  int n = 0;
  for (const Joint& j : joints) n += j.end_site ? 0 : 1;
  return n;
}

}  // namespace duet
