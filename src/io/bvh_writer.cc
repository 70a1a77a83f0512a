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

class Writer {
 public:
  explicit Writer(int decimals) : decimals_(std::clamp(decimals, 0, 17)) {}

  std::string& out() { return out_; }

  void fixed(double value) {
    // Fixed notation of any double fits: at most 309 integer digits, a sign, a point, 17 decimals.
    char buffer[400];
    const auto result =
        std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::fixed, decimals_);
    std::string_view text(buffer, static_cast<std::size_t>(result.ptr - buffer));
    // "-0.000000" reads back the same but looks like a bug in the file.
    if (text.starts_with('-') && text.find_first_not_of("0.", 1) == std::string_view::npos) {
      text.remove_prefix(1);
    }
    out_ += text;
  }

  void shortest(double value) {
    char buffer[64];
    const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
    out_.append(buffer, static_cast<std::size_t>(result.ptr - buffer));
  }

  void indent(int depth) { out_.append(static_cast<std::size_t>(depth), '\t'); }

 private:
  int decimals_;
  std::string out_;
};

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

std::string format_bvh(const Clip& clip, const BvhWriteOptions& options) {
  const Skeleton& skeleton = clip.skeleton();
  const std::size_t n = skeleton.joints.size();
  const double units = options.units_per_metre;

  // Depth-first order, children in index order. For a skeleton the reader made this is the index
  // order itself, so a read-write-read cycle keeps every joint's index.
  std::vector<std::vector<int>> children(n);
  for (std::size_t j = 1; j < n; ++j) {
    const int parent = skeleton.joints[j].parent;
    if (parent >= 0) children[static_cast<std::size_t>(parent)].push_back(static_cast<int>(j));
  }
  std::vector<int> order;
  order.reserve(n);

  Writer w(options.decimals);
  std::string& out = w.out();
  out += "HIERARCHY\n";
  if (n > 0) {
    // Explicit stack: (joint, next child to visit).
    std::vector<std::pair<int, std::size_t>> stack = {{0, 0}};
    auto open_joint = [&](int j, int depth) {
      const Joint& joint = skeleton.joints[static_cast<std::size_t>(j)];
      const bool as_end_site =
          j != 0 && joint.end_site && children[static_cast<std::size_t>(j)].empty();
      order.push_back(j);
      w.indent(depth);
      out += j == 0 ? "ROOT " : (as_end_site ? "End Site" : "JOINT ");
      if (!as_end_site) out += joint.name;
      out += '\n';
      w.indent(depth);
      out += "{\n";
      w.indent(depth + 1);
      out += "OFFSET";
      for (int axis = 0; axis < 3; ++axis) {
        out += ' ';
        w.fixed(joint.offset[axis] * units);
      }
      out += '\n';
      if (!as_end_site) {
        w.indent(depth + 1);
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
        w.indent(depth - 1);
        out += "}\n";
        stack.pop_back();
      }
    }
  }

  out += "MOTION\nFrames: ";
  out += std::to_string(clip.frame_count());
  out += "\nFrame Time: ";
  w.shortest(clip.frame_time());
  out += '\n';

  std::vector<EulerOrder> orders(n);
  for (std::size_t j = 0; j < n; ++j) orders[j] = write_order(skeleton.joints[j]);
  for (int f = 0; f < clip.frame_count(); ++f) {
    const auto translations = clip.translations_ls(f);
    const auto rotations = clip.rotations_ls(f);
    bool first = true;
    for (const int jj : order) {
      const auto j = static_cast<std::size_t>(jj);
      const Joint& joint = skeleton.joints[j];
      if (joint.channels.empty()) continue;
      Vec3 degrees = Vec3::Zero();
      bool have_angles = false;
      for (const Channel c : joint.channels) {
        if (!first) out += ' ';
        first = false;
        if (is_position_channel(c)) {
          w.fixed(translations[j][static_cast<int>(c)] * units);
          continue;
        }
        if (!have_angles) {
          degrees = euler_from_quat(rotations[j], orders[j]) * (180.0 / kPi);
          have_angles = true;
        }
        const Axis axis = static_cast<Axis>(static_cast<int>(c) - 3);
        const auto k = std::find(orders[j].begin(), orders[j].end(), axis) - orders[j].begin();
        w.fixed(degrees[static_cast<int>(k)]);
      }
    }
    out += '\n';
  }
  return std::move(out);
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
