// BVH reader: the whole text is in memory; a hand-written scanner walks it once. The hierarchy
// is parsed with an explicit stack (no recursion, so deep nesting cannot overflow the call
// stack) and the motion section with a tight std::from_chars loop that converts each frame as
// soon as its values are read.
#include <algorithm>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "duet/io/bvh.h"
#include "duet/math/rotation.h"
#include "io/text_file.h"

namespace duet {

namespace {

using io_internal::ascii_lower;
using io_internal::equals_ignore_case;
using io_internal::quoted_token;

// kPi / 180 as one factor: deg * kPi / 180 would overflow for |deg| > 5.7e307.
constexpr double kDegToRad = kPi / 180.0;

// A skeleton with more than this many joints per channel may hold at most kMaxSparseJointFrames
// joint-frames. Every joint is stored at every frame, so without this bound a skeleton of
// channel-less joints with a large Frames: value would allocate far more than the file holds.
constexpr long long kMaxJointsPerChannel = 4;
constexpr long long kMaxSparseJointFrames = 1 << 20;

inline bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}
inline bool is_brace(char c) { return c == '{' || c == '}'; }

bool starts_with_ignore_case(std::string_view text, std::string_view prefix) {
  return text.size() >= prefix.size() && equals_ignore_case(text.substr(0, prefix.size()), prefix);
}

// A token for an error message; the empty token is the end of the file.
std::string quoted_or_end(std::string_view token) {
  return token.empty() ? "end of file" : quoted_token(token);
}

enum class NumberStatus { kOk, kNotANumber, kNotFinite };

// Parses all of `token` as a decimal number. Accepts a leading '+' (std::from_chars does not) and
// values that underflow to zero; "nan", "inf" and overflowing values are kNotFinite.
NumberStatus parse_number(std::string_view token, double& value) {
  const char* begin = token.data();
  const char* end = begin + token.size();
  if (begin != end && *begin == '+') {
    ++begin;
    if (begin != end && *begin == '-') return NumberStatus::kNotANumber;
  }
  const auto [ptr, ec] = std::from_chars(begin, end, value);
  if (ptr != end || begin == end) return NumberStatus::kNotANumber;
  if (ec == std::errc::result_out_of_range) {
    // Rare path: tell underflow (a valid tiny number, read as zero) from overflow.
    const std::string copy(begin, end);
    const double approx = std::strtod(copy.c_str(), nullptr);
    if (std::isfinite(approx) && std::abs(approx) < 1.0) {
      value = *begin == '-' ? -0.0 : 0.0;
      return NumberStatus::kOk;
    }
    return NumberStatus::kNotFinite;
  }
  if (ec != std::errc()) return NumberStatus::kNotANumber;
  return std::isfinite(value) ? NumberStatus::kOk : NumberStatus::kNotFinite;
}

// Whether text[pos] ends a line: LF, or a CR not followed by LF (CRLF counts once, at the LF).
inline bool ends_line(std::string_view text, std::size_t pos) {
  const char c = text[pos];
  return c == '\n' || (c == '\r' && (pos + 1 == text.size() || text[pos + 1] != '\n'));
}

// For a token that had to be on the current line: an empty one means the line ended.
std::string quoted_on_line(std::string_view token) {
  return token.empty() ? std::string("nothing") : quoted_or_end(token);
}

struct Token {
  std::string_view text;  // empty at end of input
  int line = 0;
  bool at_end() const { return text.empty(); }
};

// Whitespace-separated tokens with line numbers; '{' and '}' are tokens of their own. Lines end
// at LF, CRLF or a lone CR.
class Scanner {
 public:
  explicit Scanner(std::string_view text) : text_(text) {}

  int line() const { return line_; }
  std::size_t position() const { return pos_; }

  void skip_space() {
    while (pos_ < text_.size() && is_space(text_[pos_])) {
      if (ends_line(text_, pos_)) ++line_;
      ++pos_;
    }
  }

  Token next() {
    skip_space();
    return read_token();
  }

  // The next token if it is on the current line; else an empty token and nothing is consumed.
  Token next_on_line() {
    const std::size_t saved_pos = pos_;
    const int saved_line = line_;
    skip_space();
    if (line_ != saved_line || pos_ == text_.size()) {
      pos_ = saved_pos;
      line_ = saved_line;
      return {{}, line_};
    }
    return read_token();
  }

  Token peek_on_line() {
    const std::size_t saved_pos = pos_;
    const int saved_line = line_;
    const Token token = next_on_line();
    pos_ = saved_pos;
    line_ = saved_line;
    return token;
  }

  Token peek() {
    const std::size_t saved_pos = pos_;
    const int saved_line = line_;
    const Token token = next();
    pos_ = saved_pos;
    line_ = saved_line;
    return token;
  }

 private:
  Token read_token() {
    const std::size_t begin = pos_;
    if (pos_ < text_.size()) {
      if (is_brace(text_[pos_])) {
        ++pos_;
      } else {
        while (pos_ < text_.size() && !is_space(text_[pos_]) && !is_brace(text_[pos_])) ++pos_;
      }
    }
    return {text_.substr(begin, pos_ - begin), line_};
  }

  std::string_view text_;
  std::size_t pos_ = 0;
  int line_ = 1;
};

// How one joint's channels map to its local transform, precomputed for the motion loop.
struct JointPlan {
  int joint = 0;
  Vec3 offset = Vec3::Zero();           // scaled; the translation components no channel animates
  int position_slot[3] = {-1, -1, -1};  // index into the frame's values per axis, or -1
  bool has_position = false;
  int rotation_slot[3] = {-1, -1, -1};  // values of the angles in listed order
  EulerOrder order{Axis::kX, Axis::kY, Axis::kZ};
  bool has_rotation = false;
};

// q * (rotation by the half angle whose cosine is c and sine s about `axis`), written out: the
// right factor has one non-zero vector component.
inline void multiply_by_axis_rotation(double q[4], int axis, double c, double s) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  switch (axis) {
    case 0:
      q[0] = w * c - x * s, q[1] = w * s + x * c, q[2] = y * c + z * s, q[3] = z * c - y * s;
      break;
    case 1:
      q[0] = w * c - y * s, q[1] = x * c - z * s, q[2] = w * s + y * c, q[3] = z * c + x * s;
      break;
    default:
      q[0] = w * c - z * s, q[1] = x * c + y * s, q[2] = y * c - x * s, q[3] = w * s + z * c;
      break;
  }
}

// Rotation from Euler angles in degrees, R = R_first * R_second * R_third (intrinsic, listed
// order): the same as quat_from_euler (tested against it), with the products written out because
// this runs once per joint per frame. A product of three unit quaternions is unit to rounding.
Quat rotation_from_degrees(const double degrees[3], const EulerOrder& order) {
  double q[4] = {1.0, 0.0, 0.0, 0.0};
  for (int k = 0; k < 3; ++k) {
    const double half = 0.5 * kDegToRad * degrees[k];
    multiply_by_axis_rotation(q, static_cast<int>(order[static_cast<std::size_t>(k)]),
                              std::cos(half), std::sin(half));
  }
  return Quat(q[0], q[1], q[2], q[3]);
}

class BvhParser {
 public:
  BvhParser(std::string_view text, const std::string& source, const BvhReadOptions& options)
      : text_(text), source_(source), options_(options), scanner_(text) {}

  Result<Clip> parse();

 private:
  Error error(int line, const std::string& reason) const {
    return make_error(source_, line, reason);
  }

  // Each returns an empty optional on success (the parsed values are stored in members).
  std::optional<Error> parse_hierarchy();
  std::optional<Error> parse_joint_head(const Token& keyword, int parent);
  std::optional<Error> parse_end_site(const Token& keyword, int parent);
  std::optional<Error> parse_offset(Joint& joint);
  std::optional<Error> parse_channels(Joint& joint, const Token& keyword);
  std::optional<Error> add_joint(Joint joint, int line, const std::string& what);
  std::optional<Error> expect(std::string_view keyword, const std::string& context);
  // A keyword like "Frames:" that may be glued to its value ("Frames:12"); returns the value.
  std::optional<Error> read_header_value(std::string_view keyword, Token& value);

  Result<Clip> parse_motion();
  Error value_count_error(std::size_t motion_begin, int motion_line, long long frames,
                          long long channels) const;

  std::string_view text_;
  const std::string& source_;
  const BvhReadOptions& options_;
  Scanner scanner_;
  std::shared_ptr<Skeleton> skeleton_ = std::make_shared<Skeleton>();
  std::vector<int> joint_lines_;                // line of each joint's keyword
  std::unordered_map<std::string, int> names_;  // joint name -> index
  std::vector<int> end_site_counts_;            // End Sites seen under each joint
};

std::optional<Error> BvhParser::expect(std::string_view keyword, const std::string& context) {
  const Token token = scanner_.next();
  if (!equals_ignore_case(token.text, keyword)) {
    return error(token.line, "expected '" + std::string(keyword) + "' " + context + ", found " +
                                 quoted_or_end(token.text));
  }
  return std::nullopt;
}

std::optional<Error> BvhParser::add_joint(Joint joint, int line, const std::string& what) {
  const auto [it, inserted] = names_.emplace(joint.name, skeleton_->joint_count());
  if (!inserted) {
    const int first = joint_lines_[static_cast<std::size_t>(it->second)];
    return error(line, "duplicate joint name '" + joint.name + "'" + what +
                           " (first used at line " + std::to_string(first) + ")");
  }
  skeleton_->joints.push_back(std::move(joint));
  joint_lines_.push_back(line);
  end_site_counts_.push_back(0);
  return std::nullopt;
}

std::optional<Error> BvhParser::parse_offset(Joint& joint) {
  const Token keyword = scanner_.next();
  if (!equals_ignore_case(keyword.text, "OFFSET")) {
    return error(keyword.line, "expected 'OFFSET' in joint '" + joint.name + "', found " +
                                   quoted_or_end(keyword.text));
  }
  for (int axis = 0; axis < 3; ++axis) {
    const Token token = scanner_.next();
    double value = 0.0;
    const NumberStatus status = parse_number(token.text, value);
    if (status == NumberStatus::kNotANumber) {
      return error(token.line, "OFFSET of joint '" + joint.name + "' needs 3 numbers, found " +
                                   quoted_or_end(token.text));
    }
    value *= options_.scale;
    if (status == NumberStatus::kNotFinite || !std::isfinite(value)) {
      return error(token.line, "OFFSET of joint '" + joint.name + "' has a non-finite value " +
                                   quoted_or_end(token.text));
    }
    joint.offset[axis] = value;
  }
  return std::nullopt;
}

std::optional<Error> BvhParser::parse_channels(Joint& joint, const Token& joint_keyword) {
  const Token keyword = scanner_.next();
  if (!equals_ignore_case(keyword.text, "CHANNELS")) {
    return error(keyword.line, "expected 'CHANNELS' after the OFFSET of " +
                                   std::string(joint_keyword.text) + " '" + joint.name +
                                   "', found " + quoted_or_end(keyword.text));
  }
  const Token count_token = scanner_.next_on_line();
  int count = -1;
  const auto [ptr, ec] = std::from_chars(count_token.text.data(),
                                         count_token.text.data() + count_token.text.size(), count);
  if (count_token.at_end() || ec != std::errc() ||
      ptr != count_token.text.data() + count_token.text.size()) {
    return error(keyword.line, "CHANNELS of joint '" + joint.name +
                                   "' must start with a channel count, found " +
                                   quoted_on_line(count_token.text));
  }
  if (count < 0 || count > 6) {
    return error(keyword.line, "CHANNELS " + std::string(count_token.text) + " in joint '" +
                                   joint.name + "': a joint has 0 to 6 channels");
  }
  bool seen[6] = {false, false, false, false, false, false};
  int rotations = 0;
  for (int k = 0; k < count; ++k) {
    const Token name = scanner_.next_on_line();
    if (name.at_end()) {
      return error(keyword.line, "CHANNELS " + std::to_string(count) + " in joint '" + joint.name +
                                     "' but the line lists " + std::to_string(k) + " channels");
    }
    std::optional<Channel> channel;
    for (int c = 0; c < 6; ++c) {
      if (equals_ignore_case(name.text, channel_name(static_cast<Channel>(c)))) {
        channel = static_cast<Channel>(c);
      }
    }
    if (!channel) {
      return error(name.line, "unknown channel name " + quoted_or_end(name.text) + " in joint '" +
                                  joint.name + "' (expected Xposition, Yposition, Zposition, " +
                                  "Xrotation, Yrotation or Zrotation)");
    }
    if (seen[static_cast<int>(*channel)]) {
      return error(name.line, "channel " + std::string(channel_name(*channel)) +
                                  " is listed twice in joint '" + joint.name + "'");
    }
    seen[static_cast<int>(*channel)] = true;
    rotations += is_position_channel(*channel) ? 0 : 1;
    joint.channels.push_back(*channel);
  }
  // Anything after the names on the same line, other than a brace, means the count is wrong.
  const Token extra = scanner_.peek_on_line();
  if (!extra.at_end() && !is_brace(extra.text[0])) {
    scanner_.next_on_line();
    int more = 0;
    while (!scanner_.next_on_line().at_end()) ++more;
    return error(keyword.line, "CHANNELS " + std::to_string(count) + " in joint '" + joint.name +
                                   "' but the line lists " + std::to_string(count + 1 + more) +
                                   " channels");
  }
  if (rotations != 0 && rotations != 3) {
    return error(keyword.line, "joint '" + joint.name + "' has " + std::to_string(rotations) +
                                   " rotation channels; a joint needs 0 or 3");
  }
  return std::nullopt;
}

// ROOT or JOINT: the name (the rest of the line up to '{'), '{', OFFSET, CHANNELS.
std::optional<Error> BvhParser::parse_joint_head(const Token& keyword, int parent) {
  Joint joint;
  joint.parent = parent;
  // Names are the tokens up to '{' or the end of the line, joined by one space ("Left Arm").
  Token brace;
  while (true) {
    const Token part = scanner_.next_on_line();
    if (part.at_end()) break;
    if (is_brace(part.text[0])) {
      brace = part;
      break;
    }
    if (!joint.name.empty()) joint.name += ' ';
    joint.name += part.text;
  }
  if (joint.name.empty()) {
    return error(keyword.line, std::string(keyword.text) + " needs a name");
  }
  if (brace.at_end()) brace = scanner_.next();
  if (brace.text != "{") {
    return error(brace.line, "expected '{' after " + std::string(keyword.text) + " " + joint.name +
                                 ", found " + quoted_or_end(brace.text));
  }
  if (auto e = parse_offset(joint)) return e;
  if (auto e = parse_channels(joint, keyword)) return e;
  return add_joint(std::move(joint), keyword.line, "");
}

std::optional<Error> BvhParser::parse_end_site(const Token& keyword, int parent) {
  const Token site = scanner_.next_on_line();
  if (!equals_ignore_case(site.text, "Site")) {
    return error(keyword.line,
                 "expected 'End Site', found 'End' followed by " + quoted_or_end(site.text));
  }
  const std::string& parent_name = skeleton_->joints[static_cast<std::size_t>(parent)].name;
  const int nth = ++end_site_counts_[static_cast<std::size_t>(parent)];
  Joint joint;
  joint.parent = parent;
  joint.end_site = true;
  joint.name = parent_name + "_End" + (nth > 1 ? std::to_string(nth) : std::string());
  if (auto e = expect("{", "after End Site")) return e;
  if (auto e = parse_offset(joint)) return e;
  const Token close = scanner_.next();
  if (close.text != "}") {
    return error(close.line, "expected '}' to close the End Site of '" + parent_name +
                                 "' (an End Site holds only an OFFSET), found " +
                                 quoted_or_end(close.text));
  }
  return add_joint(std::move(joint), keyword.line, " (End Site of '" + parent_name + "')");
}

std::optional<Error> BvhParser::parse_hierarchy() {
  if (text_.empty() || scanner_.peek().at_end()) {
    return error(0, "empty file (expected a BVH file starting with HIERARCHY)");
  }
  if (const void* nul = std::memchr(text_.data(), '\0', text_.size())) {
    const auto at = static_cast<std::size_t>(static_cast<const char*>(nul) - text_.data());
    int line = 1;
    for (std::size_t i = 0; i < at; ++i) line += ends_line(text_, i) ? 1 : 0;
    return error(line, "binary data (a NUL byte) in a BVH text file");
  }
  const Token first = scanner_.next();
  if (!equals_ignore_case(first.text, "HIERARCHY")) {
    return error(first.line, "expected 'HIERARCHY' at the start of a BVH file, found " +
                                 quoted_or_end(first.text));
  }
  const Token root = scanner_.next();
  if (!equals_ignore_case(root.text, "ROOT")) {
    return error(root.line, "expected 'ROOT' after HIERARCHY, found " + quoted_or_end(root.text));
  }
  if (auto e = parse_joint_head(root, -1)) return e;

  // Open joints, innermost last: no recursion, so deep nesting cannot overflow the stack.
  std::vector<int> open = {0};
  while (!open.empty()) {
    const int current = open.back();
    const Token token = scanner_.next();
    const std::string& name = skeleton_->joints[static_cast<std::size_t>(current)].name;
    if (token.text == "}") {
      open.pop_back();
    } else if (equals_ignore_case(token.text, "JOINT")) {
      if (auto e = parse_joint_head(token, current)) return e;
      open.push_back(skeleton_->joint_count() - 1);
    } else if (equals_ignore_case(token.text, "End")) {
      if (auto e = parse_end_site(token, current)) return e;
    } else if (token.at_end() || equals_ignore_case(token.text, "MOTION")) {
      return error(token.line, "unbalanced braces: joint '" + name + "' (opened at line " +
                                   std::to_string(joint_lines_[static_cast<std::size_t>(current)]) +
                                   ") is not closed with '}' before " + quoted_or_end(token.text));
    } else {
      return error(token.line, "expected JOINT, End Site or '}' in joint '" + name + "', found " +
                                   quoted_or_end(token.text));
    }
  }
  const Token motion = scanner_.next();
  if (motion.text == "}") {
    return error(motion.line, "unbalanced braces: '}' with no open joint");
  }
  if (equals_ignore_case(motion.text, "ROOT")) {
    return error(motion.line, "a second ROOT: only one skeleton per file is supported");
  }
  if (!equals_ignore_case(motion.text, "MOTION")) {
    return error(motion.line, motion.at_end() ? "missing MOTION section after the hierarchy"
                                              : "expected 'MOTION' after the hierarchy, found " +
                                                    quoted_or_end(motion.text));
  }
  const std::string problem = skeleton_->validate();
  if (!problem.empty()) return error(motion.line, problem);
  return std::nullopt;
}

std::optional<Error> BvhParser::read_header_value(std::string_view keyword, Token& value) {
  // "Frames:" or "Frame Time:" (two tokens); the value may be glued on ("Frames:12").
  Token token = scanner_.next();
  const int line = token.line;
  std::string_view rest;
  if (keyword == "Frame Time:") {
    if (!equals_ignore_case(token.text, "Frame")) {
      return error(line, "expected 'Frame Time:' after Frames, found " + quoted_or_end(token.text));
    }
    token = scanner_.next_on_line();
    keyword = "Time:";
  }
  if (!starts_with_ignore_case(token.text, keyword)) {
    return error(line, "expected '" + std::string(keyword == "Time:" ? "Frame Time:" : keyword) +
                           "', found " + quoted_or_end(token.text));
  }
  rest = token.text.substr(keyword.size());
  value = rest.empty() ? scanner_.next_on_line() : Token{rest, token.line};
  if (value.at_end()) value.line = line;
  return std::nullopt;
}

Error BvhParser::value_count_error(std::size_t motion_begin, int motion_line, long long frames,
                                   long long channels) const {
  // Only on the error path: count values per line to point at the first line that is off.
  const long long expected = frames * channels;
  long long total = 0;
  long long full_lines = 0;
  int line = motion_line;
  int first_bad_line = 0;
  long long first_bad_count = 0;
  int extra_line = 0;
  std::string_view extra_token;
  long long on_line = 0;
  std::size_t pos = motion_begin;
  auto end_line = [&] {
    if (channels > 0 && on_line == channels) ++full_lines;
    if (on_line != 0 && on_line != channels && first_bad_line == 0) {
      first_bad_line = line;
      first_bad_count = on_line;
    }
    on_line = 0;
  };
  while (pos < text_.size()) {
    const char c = text_[pos];
    if (ends_line(text_, pos)) {
      end_line();
      ++line;
      ++pos;
    } else if (is_space(c)) {
      ++pos;
    } else {
      const std::size_t begin = pos;
      while (pos < text_.size() && !is_space(text_[pos])) ++pos;
      if (total == expected) {
        extra_line = line;
        extra_token = text_.substr(begin, pos - begin);
      }
      ++total;
      ++on_line;
    }
  }
  end_line();
  const std::string declared = "Frames: " + std::to_string(frames) + " x " +
                               std::to_string(channels) +
                               " channels = " + std::to_string(expected) + " values";
  if (total < expected) {
    if (first_bad_line != 0) {
      return error(first_bad_line, "motion line has " + std::to_string(first_bad_count) +
                                       " values, expected " + std::to_string(channels) +
                                       "; the motion data ends after " + std::to_string(total) +
                                       " of " + declared + " (truncated file?)");
    }
    return error(line, "motion data ends after " + std::to_string(full_lines) +
                           " frames, but the header says Frames: " + std::to_string(frames) +
                           " (truncated file?)");
  }
  // A line that is off before the first extra value (or on its line, with too many values) is
  // the likely cause; otherwise the file simply has more frames than Frames: says.
  if (first_bad_line != 0 && (first_bad_line < extra_line ||
                              (first_bad_line == extra_line && first_bad_count > channels))) {
    return error(first_bad_line,
                 "motion line has " + std::to_string(first_bad_count) + " values, expected " +
                     std::to_string(channels) + "; the motion data has " + std::to_string(total) +
                     " values, " + std::to_string(total - expected) + " more than " + declared);
  }
  return error(extra_line, "extra value " + quoted_or_end(extra_token) +
                               " after the last frame: the " + "motion data has " +
                               std::to_string(total) + " values (" + std::to_string(full_lines) +
                               " frames), but " + declared);
}

Result<Clip> BvhParser::parse_motion() {
  const Skeleton& skeleton = *skeleton_;
  const long long channels = skeleton.channel_count();
  const long long joints = skeleton.joint_count();

  Token frames_token;
  if (auto e = read_header_value("Frames:", frames_token)) return *e;
  long long frames = -1;
  {
    const char* b = frames_token.text.data();
    const char* e = b + frames_token.text.size();
    const auto [ptr, ec] = std::from_chars(b, e, frames);
    if (frames_token.at_end() || ptr != e || frames < 0) {
      if (ec == std::errc::result_out_of_range && *b != '-') {
        return error(frames_token.line,
                     "Frames: " + std::string(frames_token.text) + " is out of range");
      }
      return error(frames_token.line,
                   "Frames: needs a whole number >= 0, found " + quoted_on_line(frames_token.text));
    }
  }
  const long long max_frames = std::min<long long>(options_.max_frames, INT_MAX);
  if (frames > max_frames) {
    return error(frames_token.line, "Frames: " + std::to_string(frames) + " exceeds the limit of " +
                                        std::to_string(max_frames) +
                                        " frames (BvhReadOptions::max_frames)");
  }

  Token time_token;
  if (auto e = read_header_value("Frame Time:", time_token)) return *e;
  double frame_time = 0.0;
  const NumberStatus time_status = parse_number(time_token.text, frame_time);
  if (time_status != NumberStatus::kOk || !(frame_time > 0.0)) {
    return error(time_token.line,
                 "Frame Time: must be a positive, finite number of seconds, found " +
                     quoted_on_line(time_token.text));
  }
  const double frame_rate = options_.frame_rate ? *options_.frame_rate : 1.0 / frame_time;
  if (!std::isfinite(frame_rate) || !(frame_rate > 0.0)) {
    return error(time_token.line, options_.frame_rate
                                      ? "frame rate override must be positive and finite"
                                      : "Frame Time: " + std::string(time_token.text) +
                                            " is too small (the frame rate is not finite)");
  }

  const int motion_line = scanner_.line();
  const std::size_t motion_begin = scanner_.position();
  // Never allocate more than the data can hold: n values need at least 2n - 1 bytes.
  const long long available = static_cast<long long>(text_.size() - motion_begin);
  if (channels > 0 && frames > (available + 1) / 2 / channels) {
    return error(motion_line, "Frames: " + std::to_string(frames) + " x " +
                                  std::to_string(channels) + " channels needs at least " +
                                  std::to_string(2 * frames * channels - 1) +
                                  " bytes of motion data, but only " + std::to_string(available) +
                                  " bytes follow (truncated file?)");
  }
  if (joints > kMaxJointsPerChannel * channels && frames * joints > kMaxSparseJointFrames) {
    return error(frames_token.line,
                 "Frames: " + std::to_string(frames) + " x " + std::to_string(joints) +
                     " joints is too large for a skeleton with only " + std::to_string(channels) +
                     " channels (at most " + std::to_string(kMaxSparseJointFrames) +
                     " joint-frames when there are more than " +
                     std::to_string(kMaxJointsPerChannel) + " joints per channel)");
  }

  // Per-joint plans and, per value, which joint and channel it belongs to (for messages).
  std::vector<JointPlan> plans;
  std::vector<int> value_joint;
  std::vector<Channel> value_channel;
  for (int j = 0; j < skeleton.joint_count(); ++j) {
    const Joint& joint = skeleton.joints[static_cast<std::size_t>(j)];
    if (joint.channels.empty()) continue;
    JointPlan plan;
    plan.joint = j;
    plan.offset = joint.offset;
    plan.order = joint.rotation_order();
    int rotation_index = 0;
    for (const Channel c : joint.channels) {
      const int slot = static_cast<int>(value_joint.size());
      value_joint.push_back(j);
      value_channel.push_back(c);
      if (is_position_channel(c)) {
        plan.position_slot[static_cast<int>(c)] = slot;
        plan.has_position = true;
      } else {
        plan.rotation_slot[rotation_index++] = slot;
        plan.has_rotation = true;
      }
    }
    plans.push_back(plan);
  }

  Clip clip(skeleton_, frame_rate, static_cast<int>(frames));
  std::vector<double> values(static_cast<std::size_t>(channels));
  const double scale = options_.scale;
  const char* const end = text_.data() + text_.size();
  const char* p = text_.data() + motion_begin;
  int line = motion_line;

  auto describe = [&](long long frame, std::size_t k) {
    const Joint& joint = skeleton.joints[static_cast<std::size_t>(value_joint[k])];
    return "frame " + std::to_string(frame) + " (joint '" + joint.name + "', " +
           std::string(channel_name(value_channel[k])) + ")";
  };
  auto token_at = [&](const char* begin) {
    const char* stop = begin;
    while (stop != end && !is_space(*stop)) ++stop;
    return std::string_view(begin, static_cast<std::size_t>(stop - begin));
  };

  for (int f = 0; f < frames; ++f) {
    for (std::size_t k = 0; k < values.size(); ++k) {
      while (p != end && is_space(*p)) {
        if (*p == '\n' || (*p == '\r' && (p + 1 == end || p[1] != '\n'))) ++line;
        ++p;
      }
      if (p == end) return value_count_error(motion_begin, motion_line, frames, channels);
      double v;
      const char* b = (*p == '+' && p + 1 != end && p[1] != '-') ? p + 1 : p;
      const auto [q, ec] = std::from_chars(b, end, v);
      if (ec == std::errc() && (q == end || is_space(*q)) && std::isfinite(v)) {
        values[k] = v;
        p = q;
        continue;
      }
      // Slow path: a token that is not a plain finite number.
      const std::string_view token = token_at(p);
      const NumberStatus status = parse_number(token, v);
      if (status == NumberStatus::kNotANumber) {
        return error(line,
                     "expected a number in " + describe(f, k) + ", found " + quoted_or_end(token));
      }
      if (status == NumberStatus::kNotFinite) {
        return error(line, "non-finite value " + quoted_or_end(token) + " in " + describe(f, k));
      }
      values[k] = v;
      p += token.size();
    }
    const auto translations = clip.translations_ls(f);
    const auto rotations = clip.rotations_ls(f);
    for (const JointPlan& plan : plans) {
      const auto j = static_cast<std::size_t>(plan.joint);
      if (plan.has_position) {
        Vec3 t = plan.offset;
        for (int axis = 0; axis < 3; ++axis) {
          const int slot = plan.position_slot[axis];
          if (slot < 0) continue;
          t[axis] = values[static_cast<std::size_t>(slot)] * scale;
          if (!std::isfinite(t[axis])) {
            return error(line, "position value in " + describe(f, static_cast<std::size_t>(slot)) +
                                   " is not finite after scaling by " + std::to_string(scale));
          }
        }
        translations[j] = t;
      }
      if (plan.has_rotation) {
        const double degrees[3] = {values[static_cast<std::size_t>(plan.rotation_slot[0])],
                                   values[static_cast<std::size_t>(plan.rotation_slot[1])],
                                   values[static_cast<std::size_t>(plan.rotation_slot[2])]};
        rotations[j] = rotation_from_degrees(degrees, plan.order);
      }
    }
  }
  while (p != end && is_space(*p)) ++p;
  if (p != end) return value_count_error(motion_begin, motion_line, frames, channels);
  return clip;
}

Result<Clip> BvhParser::parse() {
  if (!std::isfinite(options_.scale) || !(options_.scale > 0.0)) {
    return error(0, "scale must be positive and finite, got " + std::to_string(options_.scale));
  }
  if (options_.frame_rate && (!std::isfinite(*options_.frame_rate) || *options_.frame_rate <= 0)) {
    return error(0, "frame rate override must be positive and finite, got " +
                        std::to_string(*options_.frame_rate));
  }
  // A UTF-8 byte order mark, as some Windows tools write, is not part of the text.
  if (text_.starts_with("\xEF\xBB\xBF")) {
    text_.remove_prefix(3);
    scanner_ = Scanner(text_);
  }
  if (auto e = parse_hierarchy()) return *e;
  return parse_motion();
}

}  // namespace

Result<Clip> parse_bvh(std::string_view text, const std::string& source_name,
                       const BvhReadOptions& options) {
  BvhParser parser(text, source_name, options);
  return parser.parse();
}

Result<Clip> read_bvh(const std::string& path, const BvhReadOptions& options) {
  Result<std::string> text = io_internal::read_text_file(path);
  if (!text) return text.error();
  return parse_bvh(text.value(), path, options);
}

}  // namespace duet
