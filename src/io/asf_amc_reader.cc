// ASF/AMC reader. Both files are read whole and walked once, line by line, by a hand-written
// tokenizer; numbers go through std::from_chars. The ASF becomes a bone table (root first), the
// hierarchy is checked for unknown bones, second parents and cycles, and the AMC values are
// collected into one flat array before the Clip is filled.
//
// Conventions (checked against CMU's own viewer and the crosscheck BVH, see docs/asf-amc.md):
// an order such as `XYZ` or `dof rx ry rz` lists rotations in the order they are *applied*, so
// R = R_z * R_y * R_x (column vectors). A bone's rotation in world-aligned rest frames is
// L = C * M * C^-1, with C from its `axis` and M from the AMC values in `dof` order.
#include <algorithm>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <system_error>
#include <unordered_map>
#include <vector>

#include "duet/io/asf_amc.h"
#include "duet/math/rotation.h"
#include "io/text_file.h"

namespace duet {

namespace {

using io_internal::ascii_lower;
using io_internal::equals_ignore_case;
using io_internal::quoted_token;

// kPi / 180 as one factor: deg * kPi / 180 would overflow for |deg| > 5.7e307.
constexpr double kDegToRad = kPi / 180.0;
constexpr double kMetresPerInch = 0.0254;
constexpr const char* kRootName = "root";

// Every joint is stored at every frame, so an ASF with many bones without DOF and an AMC with
// many tiny frames could make the Clip far larger than the files. We allow at most this many
// joint-frames per byte of AMC text (CMU files need about 0.05), plus a fixed allowance.
constexpr long long kMaxJointFramesPerAmcByte = 4;
constexpr long long kJointFrameAllowance = 1 << 18;

// ------------------------------------------------------------------------------------- text

inline bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

// Splits text into lines (LF or CRLF; a stray CR counts as white space) and each line into
// white-space separated tokens. `tokens` is reused, so steady-state reading allocates nothing.
class LineTokenizer {
 public:
  explicit LineTokenizer(std::string_view text) : text_(text) {}

  enum class Status { kLine, kEnd, kBinary };

  // Reads the next line. kBinary: the line holds a control byte (stored in bad_byte()), which no
  // text file of either format contains.
  Status next(std::vector<std::string_view>& tokens) {
    tokens.clear();
    if (pos_ >= text_.size()) return Status::kEnd;
    if (line_ < INT_MAX) ++line_;
    const char* p = text_.data() + pos_;
    const char* const end = text_.data() + text_.size();
    while (p != end && *p != '\n') {
      while (p != end && is_space(*p)) ++p;
      const char* start = p;
      while (p != end && *p != '\n' && !is_space(*p)) {
        if (static_cast<unsigned char>(*p) < 0x20 || *p == 0x7f) {
          bad_byte_ = static_cast<unsigned char>(*p);
          return Status::kBinary;
        }
        ++p;
      }
      if (p != start) tokens.emplace_back(start, static_cast<std::size_t>(p - start));
    }
    pos_ = static_cast<std::size_t>(p - text_.data()) + (p != end ? 1 : 0);
    return Status::kLine;
  }

  int line() const { return line_; }
  unsigned bad_byte() const { return bad_byte_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  int line_ = 0;
  unsigned bad_byte_ = 0;
};

std::string binary_message(unsigned byte) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string hex = "0x";
  hex += kHex[(byte >> 4) & 15];
  hex += kHex[byte & 15];
  return "control byte " + hex + " in text (binary data?)";
}

bool blank(std::string_view text) {
  return std::all_of(text.begin(), text.end(), [](char c) { return is_space(c) || c == '\n'; });
}

enum class NumberStatus { kOk, kNotANumber, kNotFinite };

// Parses all of `token` as a decimal number. Accepts a leading '+' (std::from_chars does not) and
// values that underflow to zero; "nan", "inf" and overflowing values are kNotFinite unless
// `allow_infinity` (joint limits may be "-inf"/"inf").
NumberStatus parse_number(std::string_view token, double& value, bool allow_infinity = false) {
  const char* begin = token.data();
  const char* end = begin + token.size();
  if (begin != end && *begin == '+') ++begin;
  if (begin == end || *begin == '+') return NumberStatus::kNotANumber;
  const auto [ptr, ec] = std::from_chars(begin, end, value, std::chars_format::general);
  if (ptr != end) return NumberStatus::kNotANumber;
  if (ec == std::errc::result_out_of_range) {
    // Overflow, or underflow (which libstdc++ also reports): underflow has a negative exponent.
    const char* e = std::find_if(begin, end, [](char c) { return c == 'e' || c == 'E'; });
    if (e != end && e + 1 != end && e[1] == '-') {
      value = 0.0;
      return NumberStatus::kOk;
    }
    return NumberStatus::kNotFinite;
  }
  if (ec != std::errc()) return NumberStatus::kNotANumber;
  if (std::isnan(value)) return NumberStatus::kNotFinite;
  if (std::isinf(value) && !allow_infinity) return NumberStatus::kNotFinite;
  return NumberStatus::kOk;
}

std::string number_message(NumberStatus status, std::string_view token) {
  if (status == NumberStatus::kNotFinite) return quoted_token(token) + " is not a finite number";
  return "expected a number, found " + quoted_token(token);
}

// --------------------------------------------------------------------------------- the model

enum class Dof { kRx, kRy, kRz, kTx, kTy, kTz, kL };

std::optional<Dof> parse_dof(std::string_view token) {
  static constexpr std::string_view kNames[] = {"rx", "ry", "rz", "tx", "ty", "tz", "l"};
  for (std::size_t k = 0; k < std::size(kNames); ++k) {
    if (equals_ignore_case(token, kNames[k])) return static_cast<Dof>(k);
  }
  return std::nullopt;
}

bool is_rotation(Dof d) { return d <= Dof::kRz; }
bool is_translation(Dof d) { return d >= Dof::kTx && d <= Dof::kTz; }
int dof_axis(Dof d) { return static_cast<int>(d) % 3; }

// A bone of the ASF; index 0 is the root, whose `dofs` are its `order`.
struct AsfBone {
  std::string name;
  int line = 0;  // where it is defined (`begin` line, or the :root keyword)
  Vec3 direction = Vec3::Zero();
  double length = 0.0;
  Vec3 axis_angles = Vec3::Zero();  // x, y, z angles in the ASF's angle unit
  EulerOrder axis_order{Axis::kX, Axis::kY, Axis::kZ};
  std::vector<Dof> dofs;
  int limit_values = 0;  // numbers seen in `limits` (two per DOF)
  bool has_name = false, has_direction = false, has_length = false;

  int parent = -1;      // bone index; -1 for the root and for bones not (yet) in the hierarchy
  int parent_line = 0;  // the :hierarchy line that gave the parent
  std::vector<int> children;

  bool has_translation = false;
  bool has_stretch = false;               // an `l` DOF
  Quat axis_rotation = Quat::Identity();  // C
};

struct AsfSkeleton {
  double length_unit = 1.0;
  bool degrees = true;
  Vec3 root_position = Vec3::Zero();  // length units
  std::vector<AsfBone> bones;         // bones[0] is the root
};

// R = R_last * ... * R_first: rotations applied in listed order (about fixed axes).
Quat compose_applied_in_order(const EulerOrder& order, const Vec3& angles_rad_by_axis) {
  Quat q = Quat::Identity();
  for (const Axis axis : order) {
    const int a = static_cast<int>(axis);
    q = Quat(Eigen::AngleAxisd(angles_rad_by_axis[a], Vec3::Unit(a))) * q;
  }
  return q;
}

// ------------------------------------------------------------------------------------- ASF

class AsfParser {
 public:
  AsfParser(std::string_view text, const std::string& name) : lines_(text), name_(name) {}

  bool parse(AsfSkeleton& skeleton);
  const Error& error() const { return error_; }

 private:
  enum class Section { kNone, kIgnored, kUnits, kDocumentation, kRoot, kBonedata, kHierarchy };

  bool fail(int line, const std::string& reason) {
    error_ = make_error(name_, line, reason);
    return false;
  }
  bool fail(const std::string& reason) { return fail(lines_.line(), reason); }

  bool number(std::string_view token, double& value, bool allow_infinity = false) {
    const NumberStatus status = parse_number(token, value, allow_infinity);
    return status == NumberStatus::kOk || fail(number_message(status, token));
  }
  // Reads exactly `n` numbers from tokens[first..].
  bool numbers(std::string_view field, std::size_t first, int n, double* out) {
    if (tokens_.size() != first + static_cast<std::size_t>(n)) {
      return fail("expected " + std::to_string(n) + " number" + (n == 1 ? "" : "s") + " after '" +
                  std::string(field) + "', found " + std::to_string(tokens_.size() - first));
    }
    for (int k = 0; k < n; ++k) {
      if (!number(tokens_[first + static_cast<std::size_t>(k)], out[k])) return false;
    }
    return true;
  }
  bool vec3(std::string_view field, std::size_t first, Vec3& v) {
    double xyz[3];
    if (!numbers(field, first, 3, xyz)) return false;
    v = Vec3(xyz[0], xyz[1], xyz[2]);
    return true;
  }

  bool keyword(std::string_view word);
  bool units_line();
  bool root_line();
  bool bonedata_line();
  bool bone_field();
  bool limits(std::size_t first);
  bool close_bone();
  bool hierarchy_line();
  bool finish();

  LineTokenizer lines_;
  const std::string& name_;
  Error error_;
  std::vector<std::string_view> tokens_;
  AsfSkeleton* skeleton_ = nullptr;

  Section section_ = Section::kNone;
  bool seen_units_ = false, seen_root_ = false, seen_bonedata_ = false, seen_hierarchy_ = false;
  bool in_bone_ = false;
  bool last_field_was_limits_ = false;
  int hierarchy_state_ = 0;  // 0 before `begin`, 1 inside, 2 after `end`
  int hierarchy_keyword_line_ = 0;
  AsfBone bone_;  // the bone being read
  std::unordered_map<std::string, int> bone_index_;
  struct HierarchyLine {
    int line;
    std::vector<std::string> names;
  };
  std::vector<HierarchyLine> hierarchy_;
};

bool AsfParser::parse(AsfSkeleton& skeleton) {
  skeleton_ = &skeleton;
  skeleton = AsfSkeleton{};
  skeleton.bones.emplace_back();
  skeleton.bones[0].name = kRootName;
  bone_index_[kRootName] = 0;
  while (true) {
    const LineTokenizer::Status status = lines_.next(tokens_);
    if (status == LineTokenizer::Status::kEnd) break;
    if (status == LineTokenizer::Status::kBinary) return fail(binary_message(lines_.bad_byte()));
    if (tokens_.empty()) continue;
    const std::string_view first = tokens_[0];
    if (first.front() == ':') {
      if (!keyword(first)) return false;
      continue;
    }
    if (first.front() == '#') continue;  // comment line
    bool ok = true;
    switch (section_) {
      case Section::kNone:
        ok = fail("expected a ':' keyword, found " + quoted_token(first));
        break;
      case Section::kIgnored:
        ok = fail("unexpected " + quoted_token(first) + " after a one-line keyword");
        break;
      case Section::kDocumentation:
        break;  // free text
      case Section::kUnits:
        ok = units_line();
        break;
      case Section::kRoot:
        ok = root_line();
        break;
      case Section::kBonedata:
        ok = bonedata_line();
        break;
      case Section::kHierarchy:
        ok = hierarchy_line();
        break;
    }
    if (!ok) return false;
  }
  return finish();
}

bool AsfParser::keyword(std::string_view word) {
  if (in_bone_) return fail("bone block has no 'end' before " + quoted_token(word));
  if (section_ == Section::kHierarchy && hierarchy_state_ == 1) {
    return fail(":hierarchy has no 'end' before " + quoted_token(word));
  }
  auto once = [&](bool& seen) {
    if (seen) return fail("second " + std::string(word) + " section");
    seen = true;
    return true;
  };
  if (word == ":version" || word == ":name" || word == ":skin") {
    section_ = Section::kIgnored;  // the value is on the same line; we keep nothing from it
  } else if (word == ":units") {
    section_ = Section::kUnits;
    if (!once(seen_units_)) return false;
  } else if (word == ":documentation") {
    section_ = Section::kDocumentation;
  } else if (word == ":root") {
    section_ = Section::kRoot;
    if (!once(seen_root_)) return false;
    skeleton_->bones[0].line = lines_.line();
  } else if (word == ":bonedata") {
    section_ = Section::kBonedata;
    if (!once(seen_bonedata_)) return false;
  } else if (word == ":hierarchy") {
    section_ = Section::kHierarchy;
    if (!once(seen_hierarchy_)) return false;
    hierarchy_keyword_line_ = lines_.line();
  } else {
    return fail("unknown keyword " + quoted_token(word));
  }
  if (section_ != Section::kIgnored && tokens_.size() > 1) {
    return fail("unexpected " + quoted_token(tokens_[1]) + " after " + std::string(word));
  }
  return true;
}

bool AsfParser::units_line() {
  const std::string_view field = tokens_[0];
  if (tokens_.size() != 2) return fail("expected one value after " + quoted_token(field));
  if (field == "mass") {
    double mass = 0.0;
    return number(tokens_[1], mass);
  }
  if (field == "length") {
    double length = 0.0;
    if (!number(tokens_[1], length)) return false;
    if (!(length > 0.0))
      return fail("length unit must be positive, found " + quoted_token(tokens_[1]));
    skeleton_->length_unit = length;
    return true;
  }
  if (field == "angle") {
    if (equals_ignore_case(tokens_[1], "deg")) {
      skeleton_->degrees = true;
    } else if (equals_ignore_case(tokens_[1], "rad")) {
      skeleton_->degrees = false;
    } else {
      return fail("angle unit must be 'deg' or 'rad', found " + quoted_token(tokens_[1]));
    }
    return true;
  }
  return fail("unknown :units field " + quoted_token(field));
}

bool AsfParser::root_line() {
  AsfBone& root = skeleton_->bones[0];
  const std::string_view field = tokens_[0];
  if (field == "order") {
    root.dofs.clear();
    for (std::size_t k = 1; k < tokens_.size(); ++k) {
      const std::optional<Dof> dof = parse_dof(tokens_[k]);
      if (!dof || *dof == Dof::kL) {
        return fail("root order: expected TX, TY, TZ, RX, RY or RZ, found " +
                    quoted_token(tokens_[k]));
      }
      if (std::find(root.dofs.begin(), root.dofs.end(), *dof) != root.dofs.end()) {
        return fail("root order lists " + quoted_token(tokens_[k]) + " twice");
      }
      root.dofs.push_back(*dof);
    }
    return true;
  }
  if (field == "axis") {
    if (tokens_.size() != 2 || !parse_euler_order(tokens_[1], root.axis_order)) {
      return fail("root axis: expected an order such as XYZ");
    }
    return true;
  }
  if (field == "position") return vec3(field, 1, skeleton_->root_position);
  if (field == "orientation") return vec3(field, 1, root.axis_angles);
  return fail("unknown :root field " + quoted_token(field));
}

bool AsfParser::bonedata_line() {
  const std::string_view first = tokens_[0];
  if (!in_bone_) {
    if (first != "begin" || tokens_.size() != 1) {
      return fail("expected 'begin' in :bonedata, found " + quoted_token(first));
    }
    in_bone_ = true;
    bone_ = AsfBone{};
    bone_.line = lines_.line();
    last_field_was_limits_ = false;
    return true;
  }
  if (first == "end") {
    if (tokens_.size() != 1) return fail("unexpected " + quoted_token(tokens_[1]) + " after 'end'");
    return close_bone();
  }
  return bone_field();
}

bool AsfParser::bone_field() {
  const std::string_view field = tokens_[0];
  if (field.front() == '(') {  // a limits line continued
    if (!last_field_was_limits_) return fail("limits line without 'limits'");
    return limits(0);
  }
  last_field_was_limits_ = false;
  if (field == "id") {
    double id = 0.0;
    return numbers(field, 1, 1, &id);
  }
  if (field == "name") {
    if (tokens_.size() != 2) return fail("expected one name after 'name'");
    if (bone_.has_name) return fail("bone has two names");
    bone_.name = std::string(tokens_[1]);
    bone_.has_name = true;
    return true;
  }
  if (field == "direction") {
    bone_.has_direction = true;
    return vec3(field, 1, bone_.direction);
  }
  if (field == "length") {
    bone_.has_length = true;
    if (!numbers(field, 1, 1, &bone_.length)) return false;
    if (bone_.length < 0.0) return fail("bone length is negative");
    return true;
  }
  if (field == "axis") {
    // `axis 0 0 20 XYZ`: the x, y and z angles, then the order they are applied in.
    if (tokens_.size() == 5) {
      if (!parse_euler_order(tokens_[4], bone_.axis_order)) {
        return fail("axis: expected an order such as XYZ, found " + quoted_token(tokens_[4]));
      }
      tokens_.pop_back();
    }
    return vec3(field, 1, bone_.axis_angles);
  }
  if (field == "dof") {
    if (!bone_.dofs.empty()) return fail("bone has two 'dof' lines");
    for (std::size_t k = 1; k < tokens_.size(); ++k) {
      const std::optional<Dof> dof = parse_dof(tokens_[k]);
      if (!dof)
        return fail("dof: expected rx, ry, rz, tx, ty, tz or l, found " + quoted_token(tokens_[k]));
      if (std::find(bone_.dofs.begin(), bone_.dofs.end(), *dof) != bone_.dofs.end()) {
        return fail("dof lists " + quoted_token(tokens_[k]) + " twice");
      }
      bone_.dofs.push_back(*dof);
    }
    return true;
  }
  if (field == "limits") {
    last_field_was_limits_ = true;
    return limits(1);
  }
  if (field == "bodymass" || field == "cofmass") {
    double value = 0.0;
    return numbers(field, 1, 1, &value);
  }
  return fail("unknown bone field " + quoted_token(field));
}

// `limits (-160.0 20.0)`, one pair per DOF, possibly one pair per line. We check and drop them:
// the Clip has no place for limits and the AMC values are not clamped to them.
bool AsfParser::limits(std::size_t first) {
  for (std::size_t k = first; k < tokens_.size(); ++k) {
    std::string_view token = tokens_[k];
    while (!token.empty()) {
      const std::size_t paren = token.find_first_of("()");
      const std::string_view value = token.substr(0, paren);
      if (!value.empty()) {
        double limit = 0.0;
        if (parse_number(value, limit, /*allow_infinity=*/true) != NumberStatus::kOk) {
          return fail("limits: expected a number, found " + quoted_token(value));
        }
        if (bone_.limit_values == INT_MAX) return fail("too many limits");
        ++bone_.limit_values;
      }
      if (paren == std::string_view::npos) break;
      token.remove_prefix(paren + 1);
    }
  }
  return true;
}

bool AsfParser::close_bone() {
  in_bone_ = false;
  if (!bone_.has_name) return fail(bone_.line, "bone has no name");
  if (!bone_.has_direction) return fail(bone_.line, "bone '" + bone_.name + "' has no direction");
  if (!bone_.has_length) return fail(bone_.line, "bone '" + bone_.name + "' has no length");
  const std::size_t dof_count = bone_.dofs.size();
  if (bone_.limit_values != 0 && static_cast<std::size_t>(bone_.limit_values) != 2 * dof_count) {
    return fail(bone_.line, "bone '" + bone_.name + "' has " + std::to_string(dof_count) +
                                " DOF but " + std::to_string(bone_.limit_values) +
                                " limit values (expected one pair per DOF)");
  }
  const auto [it, inserted] =
      bone_index_.emplace(bone_.name, static_cast<int>(skeleton_->bones.size()));
  if (!inserted) {
    return fail(bone_.line, "bone name '" + bone_.name + "' is used twice" +
                                (bone_.name == kRootName ? " (root is the root's name)" : ""));
  }
  skeleton_->bones.push_back(std::move(bone_));
  return true;
}

bool AsfParser::hierarchy_line() {
  const std::string_view first = tokens_[0];
  if (hierarchy_state_ == 0) {
    if (first != "begin" || tokens_.size() != 1) {
      return fail("expected 'begin' in :hierarchy, found " + quoted_token(first));
    }
    hierarchy_state_ = 1;
    return true;
  }
  if (hierarchy_state_ == 2)
    return fail("unexpected " + quoted_token(first) + " after :hierarchy 'end'");
  if (first == "end" && tokens_.size() == 1) {
    hierarchy_state_ = 2;
    return true;
  }
  if (tokens_.size() < 2) return fail("hierarchy line names a parent but no children");
  HierarchyLine line{lines_.line(), {}};
  line.names.reserve(tokens_.size());
  for (const std::string_view token : tokens_) line.names.emplace_back(token);
  hierarchy_.push_back(std::move(line));
  return true;
}

bool AsfParser::finish() {
  if (in_bone_) return fail(bone_.line, "bone block has no 'end'");
  if (section_ == Section::kHierarchy && hierarchy_state_ == 1) {
    return fail(hierarchy_keyword_line_, ":hierarchy has no 'end'");
  }
  if (!seen_root_) return fail(0, "no :root section");
  std::vector<AsfBone>& bones = skeleton_->bones;

  // Parents and children, in the order the hierarchy lists them.
  for (const HierarchyLine& line : hierarchy_) {
    const auto parent_it = bone_index_.find(line.names[0]);
    if (parent_it == bone_index_.end()) {
      return fail(line.line, "hierarchy names bone " + quoted_token(line.names[0]) +
                                 ", which :bonedata does not define");
    }
    const int parent = parent_it->second;
    for (std::size_t k = 1; k < line.names.size(); ++k) {
      const auto child_it = bone_index_.find(line.names[k]);
      if (child_it == bone_index_.end()) {
        return fail(line.line, "hierarchy names bone " + quoted_token(line.names[k]) +
                                   ", which :bonedata does not define");
      }
      const int child = child_it->second;
      AsfBone& bone = bones[static_cast<std::size_t>(child)];
      if (child == 0) return fail(line.line, "root cannot be a child");
      if (child == parent) return fail(line.line, "bone '" + bone.name + "' is its own parent");
      if (bone.parent >= 0) {
        return fail(line.line, "bone '" + bone.name + "' has two parents: '" +
                                   bones[static_cast<std::size_t>(bone.parent)].name + "' (line " +
                                   std::to_string(bone.parent_line) + ") and '" +
                                   bones[static_cast<std::size_t>(parent)].name + "'");
      }
      bone.parent = parent;
      bone.parent_line = line.line;
      bones[static_cast<std::size_t>(parent)].children.push_back(child);
    }
  }
  // Every bone but the root has a parent now; one that is not reachable from the root lies on a
  // cycle (following parents from it never reaches the root).
  std::vector<char> reachable(bones.size(), 0);
  std::vector<int> stack = {0};
  reachable[0] = 1;
  while (!stack.empty()) {
    const int b = stack.back();
    stack.pop_back();
    for (const int child : bones[static_cast<std::size_t>(b)].children) {
      reachable[static_cast<std::size_t>(child)] = 1;
      stack.push_back(child);
    }
  }
  for (std::size_t b = 1; b < bones.size(); ++b) {
    if (reachable[b]) continue;
    if (bones[b].parent < 0) {
      return fail(bones[b].line, "bone '" + bones[b].name + "' is not in the :hierarchy");
    }
    // Walk up the parents until a bone repeats (that bone lies on the cycle) or until a bone
    // without a parent (a subtree hung under a bone the :hierarchy never places).
    std::vector<char> visited(bones.size(), 0);
    auto on_cycle = b;
    while (!visited[on_cycle]) {
      visited[on_cycle] = 1;
      if (bones[on_cycle].parent < 0) {
        return fail(bones[on_cycle].line,
                    "bone '" + bones[on_cycle].name + "' is not in the :hierarchy");
      }
      on_cycle = static_cast<std::size_t>(bones[on_cycle].parent);
    }
    return fail(bones[on_cycle].parent_line,
                "hierarchy has a cycle through bone '" + bones[on_cycle].name + "'");
  }

  // Axis rotations C and DOF summaries.
  const double angle_scale = skeleton_->degrees ? kDegToRad : 1.0;
  for (AsfBone& bone : bones) {
    bone.axis_rotation = compose_applied_in_order(bone.axis_order, bone.axis_angles * angle_scale);
    for (const Dof d : bone.dofs) {
      bone.has_translation = bone.has_translation || is_translation(d);
      bone.has_stretch = bone.has_stretch || d == Dof::kL;
    }
  }
  return true;
}

// ------------------------------------------------------------------------------------- AMC

// The AMC values, frame-major: values[frame * values_per_frame + bone_first_value[bone] + k].
struct AmcMotion {
  long long frame_count = 0;
  std::vector<double> values;
  std::vector<int> frame_lines;  // line of each frame number, for error messages
};

class AmcParser {
 public:
  // `joint_count`: joints of the Clip, each stored at every frame; `max_joint_frames` bounds
  // frames * joint_count.
  AmcParser(std::string_view text, const std::string& name, const AsfSkeleton& skeleton,
            long long max_frames, long long joint_count, long long max_joint_frames)
      : lines_(text),
        name_(name),
        skeleton_(skeleton),
        max_frames_(max_frames),
        joint_count_(joint_count),
        max_joint_frames_(max_joint_frames) {}

  bool parse(AmcMotion& motion, bool& degrees);
  const Error& error() const { return error_; }
  const std::vector<int>& first_value() const { return first_value_; }
  int values_per_frame() const { return values_per_frame_; }

 private:
  bool fail(int line, const std::string& reason) {
    error_ = make_error(name_, line, reason);
    return false;
  }
  bool fail(const std::string& reason) { return fail(lines_.line(), reason); }
  bool start_frame(std::string_view token);
  bool end_frame();
  bool bone_line();
  int find_bone(std::string_view name);

  LineTokenizer lines_;
  const std::string& name_;
  const AsfSkeleton& skeleton_;
  long long max_frames_;
  long long joint_count_;
  long long max_joint_frames_;
  Error error_;
  AmcMotion* motion_ = nullptr;
  std::vector<std::string_view> tokens_;

  std::vector<int> first_value_;  // per bone
  int values_per_frame_ = 0;
  std::unordered_map<std::string_view, int> index_;
  // Per bone, the frame (1-based count) of its last line: nothing is reset per frame, so a frame
  // costs its lines, not the number of bones.
  std::vector<long long> seen_in_frame_;
  int dof_bones_ = 0;            // bones that need a line in every frame
  int dof_lines_in_frame_ = 0;   // lines of such bones in the current frame
  std::vector<int> line_order_;  // bone indices in the order the first frame listed them
  std::size_t line_in_frame_ = 0;
  long long frame_number_ = -1;  // of the current frame; -1 before the first
  int frame_line_ = 0;
};

bool AmcParser::parse(AmcMotion& motion, bool& degrees) {
  motion_ = &motion;
  motion = AmcMotion{};
  const std::size_t bone_count = skeleton_.bones.size();
  first_value_.resize(bone_count);
  for (std::size_t b = 0; b < bone_count; ++b) {
    first_value_[b] = values_per_frame_;
    values_per_frame_ += static_cast<int>(skeleton_.bones[b].dofs.size());
    index_.emplace(skeleton_.bones[b].name, static_cast<int>(b));
    dof_bones_ += skeleton_.bones[b].dofs.empty() ? 0 : 1;
  }
  seen_in_frame_.assign(bone_count, 0);
  while (true) {
    const LineTokenizer::Status status = lines_.next(tokens_);
    if (status == LineTokenizer::Status::kEnd) break;
    if (status == LineTokenizer::Status::kBinary) return fail(binary_message(lines_.bad_byte()));
    if (tokens_.empty()) continue;
    const std::string_view first = tokens_[0];
    if (first.front() == '#') continue;
    if (first.front() == ':') {
      if (frame_number_ >= 0)
        return fail("keyword " + quoted_token(first) + " after the first frame");
      if (tokens_.size() != 1)
        return fail("unexpected " + quoted_token(tokens_[1]) + " after " + quoted_token(first));
      if (equals_ignore_case(first, ":FULLY-SPECIFIED")) continue;
      if (equals_ignore_case(first, ":DEGREES")) {
        degrees = true;
      } else if (equals_ignore_case(first, ":RADIANS")) {
        degrees = false;
      } else {
        return fail("unknown keyword " + quoted_token(first));
      }
      continue;
    }
    const char c = first.front();
    if (tokens_.size() == 1 && ((c >= '0' && c <= '9') || c == '-' || c == '+')) {
      if (!start_frame(first)) return false;
      continue;
    }
    if (frame_number_ < 0) return fail("bone line before the first frame number");
    if (!bone_line()) return false;
  }
  if (frame_number_ < 0) return fail(lines_.line(), "no frames");
  return end_frame();
}

bool AmcParser::start_frame(std::string_view token) {
  long long number = 0;
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), number);
  if (ptr != token.data() + token.size() ||
      (ec != std::errc() && ec != std::errc::result_out_of_range)) {
    return fail("expected a frame number, found " + quoted_token(token));
  }
  if (ec == std::errc::result_out_of_range)
    return fail("frame number " + quoted_token(token) + " is out of range");
  // A frame number is plain digits: "-0" is 0 to from_chars, but no AMC writer emits a sign.
  if (number < 0 || token.front() == '-') {
    return fail("frame number " + quoted_token(token) + " is negative");
  }
  if (frame_number_ >= 0) {
    if (!end_frame()) return false;
    if (number != frame_number_ + 1) {
      return fail("expected frame " + std::to_string(frame_number_ + 1) + " after frame " +
                  std::to_string(frame_number_) + ", found " + quoted_token(token) +
                  (number <= frame_number_ ? " (out of order)" : " (a gap)"));
    }
  }
  const long long limit = std::min<long long>(max_frames_, INT_MAX);
  if (motion_->frame_count >= limit) {
    return fail("too many frames: the limit is " + std::to_string(limit) +
                " (AsfAmcReadOptions::max_frames)");
  }
  if ((motion_->frame_count + 1) * joint_count_ > max_joint_frames_) {
    return fail("the clip would hold more than " + std::to_string(max_joint_frames_) +
                " joint-frames (" + std::to_string(joint_count_) +
                " joints at every frame), too many for the file's size: bones without DOF?");
  }
  frame_number_ = number;
  frame_line_ = lines_.line();
  ++motion_->frame_count;
  motion_->frame_lines.push_back(frame_line_);
  // The values of this frame are appended as the file gives them; the array grows with the file
  // that is actually read, never with a number the file claims.
  motion_->values.resize(motion_->values.size() + static_cast<std::size_t>(values_per_frame_));
  dof_lines_in_frame_ = 0;
  line_in_frame_ = 0;
  return true;
}

bool AmcParser::end_frame() {
  if (dof_lines_in_frame_ == dof_bones_) return true;
  for (std::size_t b = 0; b < seen_in_frame_.size(); ++b) {
    if (seen_in_frame_[b] != motion_->frame_count && !skeleton_.bones[b].dofs.empty()) {
      return fail(frame_line_, "frame " + std::to_string(frame_number_) +
                                   " has no line for bone '" + skeleton_.bones[b].name + "'");
    }
  }
  return true;
}

int AmcParser::find_bone(std::string_view name) {
  // Files list the bones in the same order every frame: try the bone the first frame had here.
  if (line_in_frame_ < line_order_.size()) {
    const int guess = line_order_[line_in_frame_];
    if (skeleton_.bones[static_cast<std::size_t>(guess)].name == name) return guess;
  }
  const auto it = index_.find(name);
  return it == index_.end() ? -1 : it->second;
}

bool AmcParser::bone_line() {
  const std::string_view name = tokens_[0];
  const int b = find_bone(name);
  if (b < 0) return fail("bone " + quoted_token(name) + " is not in the ASF");
  const auto bone = static_cast<std::size_t>(b);
  if (seen_in_frame_[bone] == motion_->frame_count) {
    return fail("bone " + quoted_token(name) + " given twice in frame " +
                std::to_string(frame_number_));
  }
  seen_in_frame_[bone] = motion_->frame_count;
  dof_lines_in_frame_ += skeleton_.bones[bone].dofs.empty() ? 0 : 1;
  if (motion_->frame_count == 1) line_order_.push_back(b);
  ++line_in_frame_;
  const std::size_t count = skeleton_.bones[bone].dofs.size();
  if (tokens_.size() - 1 != count) {
    return fail("bone " + quoted_token(name) + " has " + std::to_string(count) +
                " DOF but the line has " + std::to_string(tokens_.size() - 1) + " value" +
                (tokens_.size() == 2 ? "" : "s"));
  }
  double* out = motion_->values.data() + motion_->values.size() -
                static_cast<std::size_t>(values_per_frame_) +
                static_cast<std::size_t>(first_value_[bone]);
  for (std::size_t k = 0; k < count; ++k) {
    const NumberStatus status = parse_number(tokens_[k + 1], out[k]);
    if (status != NumberStatus::kOk) return fail(number_message(status, tokens_[k + 1]));
  }
  return true;
}

// ---------------------------------------------------------------------------- building the clip

struct BuiltSkeleton {
  std::shared_ptr<Skeleton> skeleton;
  std::vector<int> joint_of_bone;  // bone index -> joint index
};

Result<BuiltSkeleton> build_skeleton(const AsfSkeleton& asf, double scale,
                                     const std::string& name) {
  BuiltSkeleton built;
  built.skeleton = std::make_shared<Skeleton>();
  std::vector<Joint>& joints = built.skeleton->joints;
  built.joint_of_bone.assign(asf.bones.size(), -1);
  // Depth first, children in :hierarchy order; an explicit stack so deep chains cannot overflow.
  std::vector<int> stack = {0};
  while (!stack.empty()) {
    const auto b = static_cast<std::size_t>(stack.back());
    stack.pop_back();
    const AsfBone& bone = asf.bones[b];
    Joint joint;
    joint.name = bone.name;
    if (b == 0) {
      joint.offset = asf.root_position * scale;
      joint.channels = {Channel::kXposition, Channel::kYposition, Channel::kZposition,
                        Channel::kXrotation, Channel::kYrotation, Channel::kZrotation};
    } else {
      const AsfBone& parent = asf.bones[static_cast<std::size_t>(bone.parent)];
      joint.parent = built.joint_of_bone[static_cast<std::size_t>(bone.parent)];
      // The joint sits at the start of its bone, i.e. at the tip of the parent bone.
      joint.offset = parent.direction * (parent.length * scale);
      if (bone.has_translation || parent.has_stretch) {
        joint.channels = {Channel::kXposition, Channel::kYposition, Channel::kZposition};
      }
      // Every bone gets three rotation channels, like CMU's BVH conversions: L = C M C^-1 is a
      // general rotation even for a 1-DOF bone, and bones without DOF keep the layout uniform.
      joint.channels.insert(joint.channels.end(),
                            {Channel::kXrotation, Channel::kYrotation, Channel::kZrotation});
    }
    if (!joint.offset.allFinite()) {
      return make_error(name, bone.line, "bone '" + bone.name + "' has a non-finite offset");
    }
    built.joint_of_bone[b] = static_cast<int>(joints.size());
    joints.push_back(std::move(joint));
    if (b != 0 && bone.children.empty()) {
      Joint end;
      end.name = bone.name + "_End";
      end.parent = built.joint_of_bone[b];
      end.offset = bone.direction * (bone.length * scale);
      end.end_site = true;
      if (!end.offset.allFinite()) {
        return make_error(name, bone.line, "bone '" + bone.name + "' has a non-finite tip");
      }
      joints.push_back(std::move(end));
    }
    for (auto it = bone.children.rbegin(); it != bone.children.rend(); ++it) stack.push_back(*it);
  }
  const std::string problem = built.skeleton->validate();
  if (!problem.empty()) return make_error(name, 0, "invalid skeleton: " + problem);
  return built;
}

}  // namespace

Result<Clip> parse_asf_amc(std::string_view asf_text, const std::string& asf_name,
                           std::string_view amc_text, const std::string& amc_name,
                           const AsfAmcReadOptions& options) {
  if (!(options.frame_rate > 0.0) || !std::isfinite(options.frame_rate)) {
    return make_error(amc_name, 0, "frame rate must be positive and finite");
  }
  if (options.metres_per_unit &&
      (!(*options.metres_per_unit > 0.0) || !std::isfinite(*options.metres_per_unit))) {
    return make_error(asf_name, 0, "metres per unit must be positive and finite");
  }
  if (blank(asf_text)) return make_error(asf_name, 0, "empty file");
  if (blank(amc_text)) return make_error(amc_name, 0, "empty file");

  AsfSkeleton asf;
  AsfParser asf_parser(asf_text, asf_name);
  if (!asf_parser.parse(asf)) return asf_parser.error();

  // Lengths: file value / `:units length` gives inches for CMU files.
  const double scale = options.metres_per_unit.value_or(kMetresPerInch) / asf.length_unit;
  if (!std::isfinite(scale) || !(scale > 0.0)) {
    return make_error(asf_name, 0, "length unit gives no finite scale to metres");
  }
  Result<BuiltSkeleton> built_result = build_skeleton(asf, scale, asf_name);
  if (!built_result) return built_result.error();
  BuiltSkeleton& built = built_result.value();

  AmcMotion motion;
  bool degrees = asf.degrees;  // unless the AMC says :DEGREES or :RADIANS
  const long long joint_count = built.skeleton->joint_count();
  const long long max_joint_frames =
      kMaxJointFramesPerAmcByte * static_cast<long long>(amc_text.size()) + kJointFrameAllowance +
      joint_count;
  AmcParser amc_parser(amc_text, amc_name, asf, options.max_frames, joint_count, max_joint_frames);
  if (!amc_parser.parse(motion, degrees)) return amc_parser.error();

  const double angle_scale = degrees ? kDegToRad : 1.0;
  const int frames = static_cast<int>(motion.frame_count);
  Clip clip(built.skeleton, options.frame_rate, frames);
  const std::vector<int>& first_value = amc_parser.first_value();
  const auto values_per_frame = static_cast<std::size_t>(amc_parser.values_per_frame());
  std::vector<double> stretch(asf.bones.size(), 0.0);  // `l` values of the current frame
  for (int f = 0; f < frames; ++f) {
    const double* frame_values =
        motion.values.data() + static_cast<std::size_t>(f) * values_per_frame;
    const std::span<Vec3> translations = clip.translations_ls(f);
    const std::span<Quat> rotations = clip.rotations_ls(f);
    // Bones are visited in joint order, so a parent's stretch is known before its children.
    for (std::size_t b = 0; b < asf.bones.size(); ++b) {
      const AsfBone& bone = asf.bones[b];
      const auto joint = static_cast<std::size_t>(built.joint_of_bone[b]);
      const double* v = frame_values + first_value[b];
      Quat motion_rotation = Quat::Identity();  // M: applied in DOF order
      Vec3 translation = Vec3::Zero();
      double l = 0.0;
      for (std::size_t k = 0; k < bone.dofs.size(); ++k) {
        const Dof d = bone.dofs[k];
        if (is_rotation(d)) {
          motion_rotation = Quat(Eigen::AngleAxisd(v[k] * angle_scale, Vec3::Unit(dof_axis(d)))) *
                            motion_rotation;
        } else if (is_translation(d)) {
          translation[dof_axis(d)] = v[k];
        } else {
          l = v[k];
        }
      }
      stretch[b] = l;
      const Quat& c = bone.axis_rotation;
      rotations[joint] = (c * motion_rotation * c.conjugate()).normalized();
      if (b == 0) {
        translations[joint] = (asf.root_position + translation) * scale;
      } else {
        const AsfBone& parent = asf.bones[static_cast<std::size_t>(bone.parent)];
        // Translation DOF move the bone along its own axes (C); the parent's `l` stretches it.
        translations[joint] =
            parent.direction *
                ((parent.length + stretch[static_cast<std::size_t>(bone.parent)]) * scale) +
            c * (translation * scale);
      }
      if (bone.has_stretch && bone.children.empty()) {  // the End Site follows its bone
        translations[joint + 1] = bone.direction * ((bone.length + l) * scale);
      }
      if (!translations[joint].allFinite() || !rotations[joint].coeffs().allFinite() ||
          !translations[std::min(joint + 1, translations.size() - 1)].allFinite()) {
        return make_error(amc_name, motion.frame_lines[static_cast<std::size_t>(f)],
                          "bone '" + bone.name + "' has a non-finite transform (values too large)");
      }
    }
  }
  return clip;
}

Result<Clip> read_asf_amc(const std::string& asf_path, const std::string& amc_path,
                          const AsfAmcReadOptions& options) {
  Result<std::string> asf_text = io_internal::read_text_file(asf_path);
  if (!asf_text) return asf_text.error();
  Result<std::string> amc_text = io_internal::read_text_file(amc_path);
  if (!amc_text) return amc_text.error();
  return parse_asf_amc(asf_text.value(), asf_path, amc_text.value(), amc_path, options);
}

}  // namespace duet
