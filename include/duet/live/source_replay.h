// Plays a motion file in real time as if a dancer performed it: frame k is due at
// start + k / (frame rate * speed). Optionally loops. Used to try `duet serve` without a suit and
// to test the loop end to end with real motion. The viewer can pause, seek and change the speed
// while it plays (docs/protocol.md, `replay`): each delivered frame is the file's next frame, so
// speed changes the stream's rate, and the frames' time_s goes on steadily across a seek and
// stands still while paused (the follower sees a dancer who jumps elsewhere, not a clock jump).
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

// Speeds a running replay accepts (the command line accepts any positive speed).
constexpr double kReplayMinSpeed = 0.1;
constexpr double kReplayMaxSpeed = 4.0;

// What a viewer shows of a replay.
struct ReplayState {
  bool paused = false;
  double speed = 1.0;
  double position_s = 0.0;  // file time of the frame delivered last or sought (else the next)
  double duration_s = 0.0;  // of the file: frame count / frame rate
  bool loop = false;
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
  double stream_rate() const { return motion_.clip.frame_rate() * speed_; }

  // Control while playing. `now` is the caller's clock, as for poll().
  ReplayState state() const noexcept;
  // Pausing keeps the next frame; resuming delivers it when it was due, counted from now.
  void set_paused(bool paused, SteadyClock::time_point now) noexcept;
  // Moves to the file's frame at position_s (clamped into the file; false if not finite). While
  // paused, poll() delivers that one frame at once, so a viewer sees where it went.
  bool seek(double position_s, SteadyClock::time_point now) noexcept;
  // False outside [kReplayMinSpeed, kReplayMaxSpeed]. The next frame keeps its due time.
  bool set_speed(double speed, SteadyClock::time_point now) noexcept;

 private:
  ReplaySource(LoadedMotion motion, const ReplayOptions& options, std::string name);
  SteadyClock::time_point due(long long n) const noexcept;
  long long position() const noexcept { return segment_first_ + next_; }
  double clock_s(long long n) const noexcept;
  // Starts a new segment at the next frame (position and clock kept), due no earlier than now.
  void rebase(SteadyClock::time_point now) noexcept;
  void deliver(SteadyClock::time_point arrival, SourceFrame& out) noexcept;

  LoadedMotion motion_;
  ReplayOptions options_;
  std::string name_;
  SourceSkeleton skeleton_;
  double speed_ = 1.0;
  bool started_ = false;
  bool paused_ = false;
  bool preview_ = false;                 // paused, and a seek wants its frame delivered
  SteadyClock::time_point paused_at_{};  // when paused; also the preview frame's arrival
  SteadyClock::duration pause_wait_{};   // how long the next frame still had to wait then
  // The schedule since the last start, seek, speed change or resume (a segment): frame k of it
  // is the file's frame (segment_first_ + k) mod frame count, due at segment_start_ + k / rate,
  // with time_s = segment_clock_s_ + k / rate.
  SteadyClock::time_point segment_start_{};
  long long segment_first_ = 0;
  double segment_clock_s_ = 0.0;
  long long next_ = 0;   // frames of the segment delivered or skipped
  int last_frame_ = -1;  // file frame delivered last, or a seek's target
  SourceStats stats_;
};

}  // namespace duet
