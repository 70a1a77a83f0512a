// A skeleton: joints in an array, parents before children, with rest offsets and the channels a
// file animates. Immutable once built; clips share it.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "duet/math/rotation.h"
#include "duet/math/types.h"

namespace duet {

enum class Channel : int { kXposition, kYposition, kZposition, kXrotation, kYrotation, kZrotation };

std::string_view channel_name(Channel channel);
std::optional<Channel> parse_channel(std::string_view name);
inline bool is_position_channel(Channel c) { return static_cast<int>(c) <= 2; }

struct Joint {
  std::string name;
  int parent = -1;              // index into Skeleton::joints; -1 for the root
  Vec3 offset = Vec3::Zero();   // rest translation from the parent, metres
  std::vector<Channel> channels;  // as the file lists them; empty for End Sites
  bool end_site = false;        // a BVH End Site (a leaf with an offset and no channels)

  bool has_position_channels() const;
  // Euler order of the rotation channels; XYZ if the joint has none.
  EulerOrder rotation_order() const;
};

class Skeleton {
 public:
  Skeleton() = default;
  // Checks the invariants (one root at index 0, parents before children, unique names,
  // finite offsets); returns an empty string when valid, else what is wrong.
  std::string validate() const;

  std::vector<Joint> joints;

  int joint_count() const { return static_cast<int>(joints.size()); }
  // Index of the joint called `name`, or -1. End Sites are named "<parent>_End".
  int find(std::string_view name) const;
  // Total number of channels over all joints (the number of values per BVH motion line).
  int channel_count() const;
  // Number of joints that are not End Sites.
  int animated_joint_count() const;
};

}  // namespace duet
