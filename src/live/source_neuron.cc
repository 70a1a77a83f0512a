#include "duet/live/source_neuron.h"

#include <algorithm>
#include <charconv>
#include <cmath>

#include "duet/base/parse_number.h"
#include "duet/math/rotation.h"

namespace duet {

namespace {

// Larger than any position in centimetres or angle in degrees a suit reports; a value beyond it is
// garbage that would poison the follower's velocities.
constexpr double kMaxAbsValue = 1e7;

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f'; }

// Splits a record into whitespace-separated tokens, one at a time.
class Tokens {
 public:
  explicit Tokens(std::string_view text) : text_(text) {}
  bool next(std::string_view& token) {
    while (pos_ < text_.size() && is_blank(text_[pos_])) ++pos_;
    if (pos_ == text_.size()) return false;
    const std::size_t begin = pos_;
    while (pos_ < text_.size() && !is_blank(text_[pos_])) ++pos_;
    token = text_.substr(begin, pos_ - begin);
    return true;
  }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
};

// Non-finite values parse here (unlike parse_number): the caller reports them as such.
bool parse_double(std::string_view token, double& value) {
  const char* begin = token.data();
  const char* end = begin + token.size();
  if (begin != end && *begin == '+') ++begin;  // from_chars does not take a leading '+'
  const auto [ptr, ec] = std::from_chars(begin, end, value);
  return ec == std::errc() && ptr == end;
}

bool parse_int(std::string_view token) {
  return parse_number<long long>(token, PlusSign::kAllowed).has_value();
}

}  // namespace

const char* neuron_parse_name(NeuronParse status) {
  switch (status) {
    case NeuronParse::kOk:
      return "ok";
    case NeuronParse::kEmpty:
      return "empty record";
    case NeuronParse::kBadHeader:
      return "avatar name without an avatar index";
    case NeuronParse::kBadNumber:
      return "a value is not a number";
    case NeuronParse::kNonFinite:
      return "a value is not finite";
    case NeuronParse::kWrongCount:
      return "wrong number of values";
    case NeuronParse::kTooLong:
      return "record too long";
  }
  return "unknown";
}

NeuronRecordParser::NeuronRecordParser(SourceSkeleton skeleton, const NeuronStreamOptions& options)
    : skeleton_(std::move(skeleton)), options_(options) {
  expected_values_ =
      (skeleton_.skeleton ? skeleton_.skeleton->channel_count() : 0) + (options_.reference ? 6 : 0);
}

NeuronParse NeuronRecordParser::parse(std::string_view record, std::span<Vec3> translations_ls,
                                      std::span<Quat> rotations_ls) const noexcept {
  if (record.size() > options_.max_record_bytes) return NeuronParse::kTooLong;
  while (!record.empty() && (record.back() == '|' || is_blank(record.back()))) {
    record.remove_suffix(1);
  }
  const Skeleton& skeleton = *skeleton_.skeleton;
  const std::size_t joints = static_cast<std::size_t>(skeleton.joint_count());
  if (translations_ls.size() < joints || rotations_ls.size() < joints) {
    return NeuronParse::kWrongCount;  // a caller's sizing bug; never write out of bounds
  }

  Tokens tokens(record);
  std::string_view first, second;
  if (!tokens.next(first)) return NeuronParse::kEmpty;
  const bool have_second = tokens.next(second);
  double scratch = 0.0;
  // "0 Avatar00 v v v ...": an integer avatar index, then a name that is not a number.
  const bool header = have_second && !parse_double(second, scratch);
  if (header && !parse_int(first)) return NeuronParse::kBadHeader;

  // Walk the values in channel order as they come. `pending` holds tokens already read.
  std::string_view pending[2] = {first, second};
  int pending_count = header ? 0 : (have_second ? 2 : 1);
  int pending_next = 0;
  auto next_value = [&](double& value) -> NeuronParse {
    std::string_view token;
    if (pending_next < pending_count) {
      token = pending[pending_next++];
    } else if (!tokens.next(token)) {
      return NeuronParse::kWrongCount;
    }
    if (!parse_double(token, value)) return NeuronParse::kBadNumber;
    if (!std::isfinite(value) || std::abs(value) > kMaxAbsValue) return NeuronParse::kNonFinite;
    return NeuronParse::kOk;
  };

  double value = 0.0;
  if (options_.reference) {
    for (int k = 0; k < 6; ++k) {
      if (const NeuronParse s = next_value(value); s != NeuronParse::kOk) return s;
    }
  }
  const double scale = skeleton_.metres_per_unit;
  for (std::size_t j = 0; j < joints; ++j) {
    const Joint& joint = skeleton.joints[j];
    Vec3 translation = joint.offset;
    Vec3 angles_rad = Vec3::Zero();
    const EulerOrder order = joint.rotation_order();
    for (const Channel channel : joint.channels) {
      if (const NeuronParse s = next_value(value); s != NeuronParse::kOk) return s;
      const int c = static_cast<int>(channel);
      if (is_position_channel(channel)) {
        translation[c] = value * scale;
      } else {
        const auto axis = static_cast<Axis>(c - 3);
        const auto k = std::find(order.begin(), order.end(), axis) - order.begin();
        if (k < 3) angles_rad[static_cast<int>(k)] = deg_to_rad(value);
      }
    }
    translations_ls[j] = translation;
    rotations_ls[j] = quat_from_euler(angles_rad, order);
  }
  std::string_view extra;
  if (pending_next < pending_count || tokens.next(extra)) return NeuronParse::kWrongCount;
  return NeuronParse::kOk;
}

NeuronSource::NeuronSource(SourceSkeleton skeleton, const NeuronStreamOptions& options,
                           std::string name)
    : parser_(std::move(skeleton), options),
      options_(options),
      name_(std::move(name)),
      queue_(parser_.source_skeleton().joint_count(), options.queue_frames) {
  pending_.reserve(options_.max_record_bytes);
}

void NeuronSource::feed(std::string_view bytes, SteadyClock::time_point arrival) noexcept {
  while (!bytes.empty()) {
    const std::size_t end = bytes.find_first_of("\n\r|");
    const std::string_view part = bytes.substr(0, end);
    if (!overlong_) {
      if (pending_.size() + part.size() > options_.max_record_bytes) {
        overlong_ = true;
        pending_.clear();
      } else {
        pending_.append(part);  // within the reserved capacity: no allocation
      }
    }
    if (end == std::string_view::npos) return;
    finish_record(arrival);
    bytes.remove_prefix(end + 1);
  }
}

void NeuronSource::end_record(SteadyClock::time_point arrival) noexcept { finish_record(arrival); }

void NeuronSource::finish_record(SteadyClock::time_point arrival) noexcept {
  NeuronParse status = NeuronParse::kTooLong;
  if (!overlong_) {
    SourceFrame& slot = queue_.begin_push();
    status = parser_.parse(pending_, slot.translations_ls, slot.rotations_ls);
    if (status == NeuronParse::kOk) {
      if (!have_epoch_) {
        have_epoch_ = true;
        epoch_ = arrival;
      }
      slot.time_s = std::chrono::duration<double>(arrival - epoch_).count();
      slot.arrival = arrival;
      queue_.commit_push();
    }
  }
  overlong_ = false;
  pending_.clear();
  if (status != NeuronParse::kOk && status != NeuronParse::kEmpty) {
    ++stats_.rejected;
    last_rejection_ = status;
  }
}

bool NeuronSource::poll(SteadyClock::time_point /*now*/, SourceFrame& out) noexcept {
  if (!queue_.pop(out)) return false;
  ++stats_.frames;
  return true;
}

SourceStats NeuronSource::stats() const noexcept {
  SourceStats s = stats_;
  s.dropped = queue_.dropped();
  return s;
}

}  // namespace duet
