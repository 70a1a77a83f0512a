// A live BVH stream as Perception Neuron's Axis software broadcasts it: one text record of channel
// values per sample, in the channel order of a BVH header that Axis exports for the same
// skeleton (`--source-skeleton HEADER.bvh`). A record looks like
//
//   0 Avatar00 0.00 91.2 -3.1 1.52 -0.73 ... 0.41 ||
//
// an avatar index and name (optional), the values (positions in the header's units, rotations in
// degrees, channel order as the header lists), and "||" (or a newline) to end it. Axis can add a
// reference bone (6 values first, "with reference"): set NeuronStreamOptions::reference. Plain BVH
// motion lines (values only, newline-terminated) parse too.
//
// The parser is strict about what it accepts and never trusts the stream: a record with the wrong
// number of values, a token that is not a number, or a value that is not finite is rejected and
// counted, and the stream goes on with the next record.
#pragma once

#include <string>
#include <string_view>

#include "duet/live/source_frame.h"

namespace duet {

struct NeuronStreamOptions {
  bool reference = false;  // each record starts with 6 values of a reference bone (skipped)
  // A record longer than this is rejected (and the bytes up to its end are discarded), so a stream
  // without terminators cannot make us buffer without bound.
  std::size_t max_record_bytes = 64 * 1024;
  int queue_frames = 8;  // frames kept between polls; older ones are dropped when it overflows
};

enum class NeuronParse {
  kOk,
  kEmpty,       // only whitespace: not a record
  kBadHeader,   // an avatar name not preceded by an integer avatar index
  kBadNumber,   // a token that is not a number
  kNonFinite,   // nan, inf, or a value too large to be a position or angle
  kWrongCount,  // not as many values as the skeleton has channels
  kTooLong,     // longer than max_record_bytes
};
const char* neuron_parse_name(NeuronParse status);

// Parses one record into a local pose. No allocation; safe on the live path.
class NeuronRecordParser {
 public:
  NeuronRecordParser(SourceSkeleton skeleton, const NeuronStreamOptions& options);

  // `record` without its terminator (a trailing "||" is tolerated). On success fills every joint's
  // local translation (metres) and rotation; on failure leaves them in an unspecified state.
  NeuronParse parse(std::string_view record, std::span<Vec3> translations_ls,
                    std::span<Quat> rotations_ls) const noexcept;

  // Values a record must hold: the skeleton's channels, plus 6 with a reference bone.
  int expected_values() const { return expected_values_; }
  const SourceSkeleton& source_skeleton() const { return skeleton_; }

 private:
  SourceSkeleton skeleton_;
  NeuronStreamOptions options_;
  int expected_values_ = 0;
};

// The source: feed it bytes as they arrive (a TCP stream split anywhere, or UDP datagrams), poll
// frames out. Records end at '\n', '\r' or '|'; empty records are ignored. Frame times are the
// arrival times (the stream carries none), in seconds since the first byte arrived.
class NeuronSource final : public FrameSource {
 public:
  NeuronSource(SourceSkeleton skeleton, const NeuronStreamOptions& options, std::string name);

  // Consumes stream bytes; complete records become frames (or rejections).
  void feed(std::string_view bytes, SteadyClock::time_point arrival) noexcept;
  // Ends the pending record, if any (end of a UDP datagram, or the TCP connection closed).
  void end_record(SteadyClock::time_point arrival) noexcept;

  const SourceSkeleton& source_skeleton() const noexcept override {
    return parser_.source_skeleton();
  }
  std::string describe() const override { return name_; }
  bool poll(SteadyClock::time_point now, SourceFrame& out) noexcept override;
  SourceStats stats() const noexcept override;

  // Why the most recent record was rejected (kOk if none was), for log lines.
  NeuronParse last_rejection() const { return last_rejection_; }

 private:
  void finish_record(SteadyClock::time_point arrival) noexcept;

  NeuronRecordParser parser_;
  NeuronStreamOptions options_;
  std::string name_;
  FrameQueue queue_;
  std::string pending_;    // the record being received; capacity reserved once
  bool overlong_ = false;  // the pending record exceeded the limit: discard to its end
  bool have_epoch_ = false;
  SteadyClock::time_point epoch_{};
  SourceStats stats_;
  NeuronParse last_rejection_ = NeuronParse::kOk;
};

}  // namespace duet
