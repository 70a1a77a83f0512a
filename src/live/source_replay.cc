#include "duet/live/source_replay.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace duet {

Result<ReplaySource> ReplaySource::create(LoadedMotion motion, const ReplayOptions& options,
                                          std::string name) {
  const Clip& clip = motion.clip;
  if (clip.frame_count() < 1) return Error{name + ": the replay file has no frames"};
  if (!(clip.frame_rate() > 0.0) || !std::isfinite(clip.frame_rate())) {
    return Error{name + ": the replay file has no valid frame rate"};
  }
  if (!(options.speed > 0.0) || !std::isfinite(options.speed)) {
    return Error{name + ": replay speed must be positive"};
  }
  if (!(options.start_s >= 0.0) || options.start_s >= clip.duration()) {
    return Error{name + fmt::format(": replay start {} s is outside the file ({:.2f} s)",
                                    options.start_s, clip.duration())};
  }
  return ReplaySource(std::move(motion), options, std::move(name));
}

ReplaySource::ReplaySource(LoadedMotion motion, const ReplayOptions& options, std::string name)
    : motion_(std::move(motion)), options_(options), name_(std::move(name)), speed_(options.speed) {
  skeleton_.skeleton = motion_.clip.skeleton_ptr();
  skeleton_.roles = motion_.roles;
  skeleton_.metres_per_unit = motion_.metres_per_unit;
  skeleton_.frame_rate = stream_rate();
  segment_first_ = std::clamp(static_cast<int>(std::lround(options_.start_s * clip().frame_rate())),
                              0, clip().frame_count() - 1);
}

std::string ReplaySource::describe() const {
  return fmt::format("replay of {} ({} frames at {:g} Hz, speed {:g}{})", name_,
                     clip().frame_count(), clip().frame_rate(), speed_,
                     options_.loop ? ", looping" : "");
}

void ReplaySource::start(SteadyClock::time_point now) noexcept {
  started_ = true;
  segment_start_ = now;
  segment_clock_s_ = 0.0;
  next_ = 0;
}

SteadyClock::time_point ReplaySource::due(long long n) const noexcept {
  const double seconds = static_cast<double>(n) / stream_rate();
  return segment_start_ +
         std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(seconds));
}

double ReplaySource::clock_s(long long n) const noexcept {
  return segment_clock_s_ + static_cast<double>(n) / stream_rate();
}

bool ReplaySource::finished() const noexcept {
  return !options_.loop && position() >= clip().frame_count();
}

std::optional<SteadyClock::time_point> ReplaySource::next_due() const noexcept {
  if (finished()) return std::nullopt;
  if (!started_) return SteadyClock::time_point{};
  if (paused_) {
    if (preview_) return paused_at_;
    return std::nullopt;
  }
  return due(next_);
}

void ReplaySource::rebase(SteadyClock::time_point now) noexcept {
  const SteadyClock::time_point next_due = due(next_);
  segment_clock_s_ = clock_s(next_);
  segment_first_ = position();
  // A replay that ended (or stalled) long ago starts again now rather than skipping ahead.
  segment_start_ = std::max(now, next_due);
  next_ = 0;
}

void ReplaySource::set_paused(bool paused, SteadyClock::time_point now) noexcept {
  if (!started_) start(now);
  if (paused == paused_) return;
  if (paused) {
    rebase(now);
    // Remember how long the next frame still had to wait.
    paused_at_ = now;
    pause_wait_ = segment_start_ - now;
    paused_ = true;
    return;
  }
  paused_ = false;
  preview_ = false;
  segment_start_ = now + pause_wait_;
  next_ = 0;
}

bool ReplaySource::seek(double position_s, SteadyClock::time_point now) noexcept {
  if (!std::isfinite(position_s)) return false;
  if (!started_) start(now);
  const int target = std::clamp(
      static_cast<int>(std::lround(std::clamp(position_s * clip().frame_rate(), -1.0,
                                              static_cast<double>(clip().frame_count())))),
      0, clip().frame_count() - 1);
  last_frame_ = target;  // where the viewer is now, before the frame comes
  if (paused_) {
    // The clock of the next frame stays; the frame comes at once, as a preview.
    segment_first_ = target;
    next_ = 0;
    preview_ = true;
    paused_at_ = now;
    pause_wait_ = {};
    return true;
  }
  rebase(now);
  segment_first_ = target;
  return true;
}

bool ReplaySource::set_speed(double speed, SteadyClock::time_point now) noexcept {
  if (!(speed >= kReplayMinSpeed && speed <= kReplayMaxSpeed)) return false;
  if (!started_) start(now);
  if (!paused_) rebase(now);
  speed_ = speed;
  return true;
}

ReplayState ReplaySource::state() const noexcept {
  ReplayState s;
  s.paused = paused_;
  s.speed = speed_;
  const int n = clip().frame_count();
  const long long frame = last_frame_ >= 0 ? last_frame_ : position() % n;
  s.position_s = static_cast<double>(std::min<long long>(frame, n - 1)) / clip().frame_rate();
  s.duration_s = static_cast<double>(n) / clip().frame_rate();
  s.loop = options_.loop;
  return s;
}

void ReplaySource::deliver(SteadyClock::time_point arrival, SourceFrame& out) noexcept {
  const int n = clip().frame_count();
  const long long index = position();
  const int frame = static_cast<int>(options_.loop ? index % n : index);
  out.time_s = clock_s(next_);
  out.arrival = arrival;
  const auto translations = clip().translations_ls(frame);
  const auto rotations = clip().rotations_ls(frame);
  const std::size_t count = std::min(out.translations_ls.size(), translations.size());
  std::copy_n(translations.begin(), count, out.translations_ls.begin());
  std::copy_n(rotations.begin(), count, out.rotations_ls.begin());
  last_frame_ = frame;
  ++next_;
  ++stats_.frames;
}

bool ReplaySource::poll(SteadyClock::time_point now, SourceFrame& out) noexcept {
  if (!started_) start(now);
  if (finished()) return false;
  if (paused_) {
    if (!preview_) return false;
    preview_ = false;
    deliver(now, out);
    // The clock moves on by one frame, so the frame after the preview is not a step back.
    segment_clock_s_ = clock_s(next_);
    segment_first_ = position();
    next_ = 0;
    return true;
  }
  if (now < due(next_)) return false;
  const std::chrono::duration<double> lag = now - due(next_);
  if (lag.count() > options_.max_lag_s) {
    // Skip to the frame due now; the skipped frames count as dropped.
    const auto now_index = static_cast<long long>(
        std::chrono::duration<double>(now - segment_start_).count() * stream_rate());
    long long target = std::max(now_index, next_);
    if (!options_.loop)
      target = std::min<long long>(target, clip().frame_count() - 1 - segment_first_);
    stats_.dropped += target - next_;
    next_ = target;
  }
  deliver(due(next_), out);
  return true;
}

}  // namespace duet
