// Plays a motion file in real time as if a dancer performed it: frame k is due at
// start + k / (frame rate * speed). Optionally loops. Used to try `duet serve` without a suit and
// to test the loop end to end with real motion.
#pragma once

#include "duet/io/motion_file.h"
#include "duet/live/source_frame.h"

namespace duet {

struct ReplayOptions {
  double speed = 1.0;    // playback speed; 2 plays a 60 Hz file as a 120 Hz stream
  bool loop = false;     // start over after the last frame (the root jumps back)
  double start_s = 0.0;  // skip this much of the file
  // When the loop falls further behind than this (the process was stopped, the machine stalled),
  // the replay skips ahead to the frame due now instead of delivering a burst of stale frames.
  double max_lag_s = 0.25;
};

class ReplaySource final : public FrameSource {
 public:
  // `motion` must have at least one frame and a positive frame rate (checked by create()).
  static Result<ReplaySource> create(LoadedMotion motion, const ReplayOptions& options,
                                     std::string name);

  const SourceSkeleton& source_skeleton() const noexcept override { return skeleton_; }
  std::string describe() const override;

  void start(SteadyClock::time_point now) noexcept override;
  std::optional<SteadyClock::time_point> next_due() const noexcept override;
  // The frame's arrival is its due time, so latency includes any lateness of the caller.
  bool poll(SteadyClock::time_point now, SourceFrame& out) noexcept override;
  bool finished() const noexcept override;
  SourceStats stats() const noexcept override { return stats_; }

  const Clip& clip() const { return motion_.clip; }
  double stream_rate() const { return motion_.clip.frame_rate() * options_.speed; }

 private:
  ReplaySource(LoadedMotion motion, const ReplayOptions& options, std::string name);
  SteadyClock::time_point due(long long n) const noexcept;

  LoadedMotion motion_;
  ReplayOptions options_;
  std::string name_;
  SourceSkeleton skeleton_;
  int first_frame_ = 0;
  bool started_ = false;
  SteadyClock::time_point start_{};
  long long next_ = 0;  // frames delivered or skipped since start
  SourceStats stats_;
};

}  // namespace duet
