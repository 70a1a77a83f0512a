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
    : motion_(std::move(motion)), options_(options), name_(std::move(name)) {
  skeleton_.skeleton = motion_.clip.skeleton_ptr();
  skeleton_.roles = motion_.roles;
  skeleton_.metres_per_unit = motion_.metres_per_unit;
  skeleton_.frame_rate = stream_rate();
  first_frame_ = std::clamp(static_cast<int>(std::lround(options_.start_s * clip().frame_rate())),
                            0, clip().frame_count() - 1);
}

std::string ReplaySource::describe() const {
  return fmt::format("replay of {} ({} frames at {:g} Hz, speed {:g}{})", name_,
                     clip().frame_count(), clip().frame_rate(), options_.speed,
                     options_.loop ? ", looping" : "");
}

void ReplaySource::start(SteadyClock::time_point now) noexcept {
  started_ = true;
  start_ = now;
  next_ = 0;
}

SteadyClock::time_point ReplaySource::due(long long n) const noexcept {
  const double seconds = static_cast<double>(n) / stream_rate();
  return start_ +
         std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(seconds));
}

bool ReplaySource::finished() const noexcept {
  return !options_.loop && first_frame_ + next_ >= clip().frame_count();
}

std::optional<SteadyClock::time_point> ReplaySource::next_due() const noexcept {
  if (finished()) return std::nullopt;
  if (!started_) return SteadyClock::time_point{};
  return due(next_);
}

bool ReplaySource::poll(SteadyClock::time_point now, SourceFrame& out) noexcept {
  if (!started_) start(now);
  if (finished() || now < due(next_)) return false;
  const std::chrono::duration<double> lag = now - due(next_);
  if (lag.count() > options_.max_lag_s) {
    // Skip to the frame due now; the skipped frames count as dropped.
    const auto now_index =
        static_cast<long long>(std::chrono::duration<double>(now - start_).count() * stream_rate());
    long long target = std::max(now_index, next_);
    if (!options_.loop)
      target = std::min<long long>(target, clip().frame_count() - 1 - first_frame_);
    stats_.dropped += target - next_;
    next_ = target;
  }
  const int n = clip().frame_count();
  const long long index = first_frame_ + next_;
  const int frame = static_cast<int>(options_.loop ? index % n : index);
  out.time_s = static_cast<double>(next_) / stream_rate();
  out.arrival = due(next_);
  const auto translations = clip().translations_ls(frame);
  const auto rotations = clip().rotations_ls(frame);
  const std::size_t count = std::min(out.translations_ls.size(), translations.size());
  std::copy_n(translations.begin(), count, out.translations_ls.begin());
  std::copy_n(rotations.begin(), count, out.rotations_ls.begin());
  ++next_;
  ++stats_.frames;
  return true;
}

}  // namespace duet
