// BVH writer: hierarchy depth-first with tab indentation, then one motion line per frame. Numbers
// go through std::to_chars (no streams, no locale).
#include <algorithm>
#include <charconv>
#include <cmath>
#include <string>
#include <vector>

#include "duet/io/atomic_write.h"
#include "duet/io/bvh.h"
#include "duet/math/rotation.h"

namespace duet {

namespace {

// Fixed notation of any double fits: at most 309 integer digits, a sign, a point, 17 decimals.
void append_fixed(std::string& out, double value, int decimals) {
  char buffer[400];
  const auto result =
      std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::fixed, decimals);
  std::string_view text(buffer, static_cast<std::size_t>(result.ptr - buffer));
  // "-0.000000" reads back the same but looks like a bug in the file.
  if (text.starts_with('-') && text.find_first_not_of("0.", 1) == std::string_view::npos) {
    text.remove_prefix(1);
  }
  out += text;
}

void append_shortest(std::string& out, double value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, static_cast<std::size_t>(result.ptr - buffer));
}

int clamp_decimals(int decimals) { return std::clamp(decimals, 0, 17); }

// Children of every joint, in index order.
std::vector<std::vector<int>> children_of(const Skeleton& skeleton) {
  std::vector<std::vector<int>> children(skeleton.joints.size());
  for (std::size_t j = 1; j < skeleton.joints.size(); ++j) {
    const int parent = skeleton.joints[j].parent;
    if (parent >= 0) children[static_cast<std::size_t>(parent)].push_back(static_cast<int>(j));
  }
  return children;
}

// Joints depth first, children in index order: the order the hierarchy lists them. For a
// skeleton the reader made this is the index order itself, so a read-write-read cycle keeps
// every joint's index.
std::vector<int> hierarchy_order(const Skeleton& skeleton) {
  std::vector<int> order;
  if (skeleton.joints.empty()) return order;
  const std::vector<std::vector<int>> children = children_of(skeleton);
  std::vector<std::pair<int, std::size_t>> stack = {{0, 0}};  // (joint, next child to visit)
  order.push_back(0);
  while (!stack.empty()) {
    auto& [j, next] = stack.back();
    const auto& kids = children[static_cast<std::size_t>(j)];
    if (next < kids.size()) {
      const int child = kids[next++];
      order.push_back(child);
      stack.emplace_back(child, 0);
    } else {
      stack.pop_back();
    }
  }
  return order;
}

// The Euler order a joint's rotation channels are written in. For a joint that lists all three
// rotation axes this is Joint::rotation_order(); for one that lists fewer (not produced by the
// reader) the missing axes follow in X, Y, Z order and only the listed angles are written.
EulerOrder write_order(const Joint& joint) {
  EulerOrder order{};
  bool used[3] = {false, false, false};
  std::size_t n = 0;
  for (const Channel c : joint.channels) {
    if (is_position_channel(c)) continue;
    const int axis = static_cast<int>(c) - 3;
    if (used[axis] || n == 3) continue;
    used[axis] = true;
    order[n++] = static_cast<Axis>(axis);
  }
  for (int axis = 0; axis < 3; ++axis) {
    if (!used[axis]) order[n++] = static_cast<Axis>(axis);
  }
  return order;
}

}  // namespace

BvhFrameFormatter::BvhFrameFormatter(const Skeleton& skeleton, const BvhWriteOptions& options)
    : skeleton_(&skeleton),
      order_(hierarchy_order(skeleton)),
      units_per_metre_(options.units_per_metre),
      decimals_(clamp_decimals(options.decimals)) {
  euler_.reserve(skeleton.joints.size());
  for (const Joint& joint : skeleton.joints) euler_.push_back(write_order(joint));
}

void BvhFrameFormatter::append(std::span<const Vec3> translations_ls,
                               std::span<const Quat> rotations_ls, std::string& out) const {
  bool first = true;
  for (const int jj : order_) {
    const auto j = static_cast<std::size_t>(jj);
    const Joint& joint = skeleton_->joints[j];
    if (joint.channels.empty()) continue;
    Vec3 degrees = Vec3::Zero();
    bool have_angles = false;
    for (const Channel c : joint.channels) {
      if (!first) out += ' ';
      first = false;
      if (is_position_channel(c)) {
        append_fixed(out, translations_ls[j][static_cast<int>(c)] * units_per_metre_, decimals_);
        continue;
      }
      if (!have_angles) {
        degrees = euler_from_quat(rotations_ls[j], euler_[j]) * (180.0 / kPi);
        have_angles = true;
      }
      const Axis axis = static_cast<Axis>(static_cast<int>(c) - 3);
      const auto k = std::find(euler_[j].begin(), euler_[j].end(), axis) - euler_[j].begin();
      append_fixed(out, degrees[static_cast<int>(k)], decimals_);
    }
  }
}

std::string format_bvh(const Clip& clip, const BvhWriteOptions& options) {
  const Skeleton& skeleton = clip.skeleton();
  const std::size_t n = skeleton.joints.size();
  const double units = options.units_per_metre;
  const int decimals = clamp_decimals(options.decimals);
  const std::vector<std::vector<int>> children = children_of(skeleton);

  std::string out = "HIERARCHY\n";
  auto indent = [&out](int depth) { out.append(static_cast<std::size_t>(depth), '\t'); };
  if (n > 0) {
    // Explicit stack: (joint, next child to visit); the same walk as hierarchy_order().
    std::vector<std::pair<int, std::size_t>> stack = {{0, 0}};
    auto open_joint = [&](int j, int depth) {
      const Joint& joint = skeleton.joints[static_cast<std::size_t>(j)];
      const bool as_end_site =
          j != 0 && joint.end_site && children[static_cast<std::size_t>(j)].empty();
      indent(depth);
      out += j == 0 ? "ROOT " : (as_end_site ? "End Site" : "JOINT ");
      if (!as_end_site) out += joint.name;
      out += '\n';
      indent(depth);
      out += "{\n";
      indent(depth + 1);
      out += "OFFSET";
      for (int axis = 0; axis < 3; ++axis) {
        out += ' ';
        append_fixed(out, joint.offset[axis] * units, decimals);
      }
      out += '\n';
      if (!as_end_site) {
        indent(depth + 1);
        out += "CHANNELS ";
        out += std::to_string(joint.channels.size());
        for (const Channel c : joint.channels) {
          out += ' ';
          out += channel_name(c);
        }
        out += '\n';
      }
    };
    open_joint(0, 0);
    while (!stack.empty()) {
      auto& [j, next] = stack.back();
      const auto& kids = children[static_cast<std::size_t>(j)];
      const int depth = static_cast<int>(stack.size());
      if (next < kids.size()) {
        const int child = kids[next++];
        open_joint(child, depth);
        stack.emplace_back(child, 0);
      } else {
        indent(depth - 1);
        out += "}\n";
        stack.pop_back();
      }
    }
  }

  out += "MOTION\nFrames: ";
  out += std::to_string(clip.frame_count());
  out += "\nFrame Time: ";
  append_shortest(out, clip.frame_time());
  out += '\n';

  const BvhFrameFormatter formatter(skeleton, options);
  for (int f = 0; f < clip.frame_count(); ++f) {
    formatter.append(clip.translations_ls(f), clip.rotations_ls(f), out);
    out += '\n';
  }
  return out;
}

Status write_bvh(const Clip& clip, const std::string& path, const BvhWriteOptions& options) {
  if (clip.skeleton_ptr() == nullptr)
    return make_error(path, 0, "cannot write: clip has no skeleton");
  const std::string problem = clip.skeleton().validate();
  if (!problem.empty()) return make_error(path, 0, "cannot write: invalid skeleton: " + problem);
  if (!std::isfinite(clip.frame_rate()) || clip.frame_rate() <= 0.0) {
    return make_error(path, 0, "cannot write: frame rate must be positive and finite");
  }
  if (!std::isfinite(options.units_per_metre) || options.units_per_metre <= 0.0) {
    return make_error(path, 0, "cannot write: units_per_metre must be positive and finite");
  }
  return write_file_atomically(path, format_bvh(clip, options));
}

}  // namespace duet
