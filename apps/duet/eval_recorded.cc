#include "eval_recorded.h"

#include <fmt/format.h>

#include <cmath>
#include <memory>
#include <optional>

#include "duet/base/parse_number.h"
#include "duet/eval/performance.h"
#include "duet/io/motion_argument.h"

namespace duet::app {

namespace {

// The library index of `word`: a take's name, else a take index; -1 when neither.
int find_take(const DuetLibrary& library, const std::string& word) {
  const auto& takes = library.takes();
  for (std::size_t k = 0; k < takes.size(); ++k) {
    if (takes[k].name == word) return static_cast<int>(k);
  }
  const std::optional<int> index = parse_number<int>(word);
  return index && *index >= 0 && *index < static_cast<int>(takes.size()) ? *index : -1;
}

std::string take_names(const DuetLibrary& library) {
  std::string names;
  for (const DuetTake& take : library.takes()) names += (names.empty() ? "" : ", ") + take.name;
  return names;
}

// A recording of a take lasts as long as the take. The same number of frames at another rate is
// the sign of a wrong header (the CMU salsa BVH files say 120 fps, the takes are 60 Hz): the
// truth, frame i at the take's moment i / rate, would be off by the ratio on every frame and the
// case would score near 0 with hardly a frame lost.
std::optional<std::string> rate_disagreement(const Clip& recording, const Clip& take) {
  const int frames = recording.frame_count();
  const int take_frames = take.frame_count();
  const double same_frames = std::max(2.0, 0.02 * take_frames);
  const double rate_ratio = recording.frame_rate() / take.frame_rate();
  if (std::abs(frames - take_frames) > same_frames || std::abs(rate_ratio - 1.0) <= 0.05) {
    return std::nullopt;
  }
  return fmt::format(
      "the recording has {} frames like the take ({}), but at {:g} fps it lasts {:.1f} s against "
      "the take's {:.1f} s at {:g} fps: one of the two frame rates is wrong (--recorded-fps {:g} "
      "reads the recording at the take's; --fps sets the library's)",
      frames, take_frames, recording.frame_rate(), recording.duration(), take.duration(),
      take.frame_rate(), take.frame_rate());
}

}  // namespace

Result<std::vector<EvalCase>> load_recorded_cases(const std::vector<std::string>& entries,
                                                  const MotionLoadOptions& load_options,
                                                  const DuetLibrary& library) {
  std::vector<EvalCase> cases;
  for (const std::string& entry : entries) {
    const std::string where = "--recorded " + entry;
    const std::size_t equals = entry.find('=');
    if (equals == std::string::npos || equals == 0 || equals + 1 == entry.size()) {
      return Error{where + ": expected TAKE=FILE, e.g. 01=60.asf+60_01.amc"};
    }
    const std::string take_word = entry.substr(0, equals);
    const int take = find_take(library, take_word);
    if (take < 0) {
      return Error{where + ": no take '" + take_word +
                   "' in the library (its takes: " + take_names(library) + ")"};
    }
    Result<std::vector<std::string>> paths = split_motion_argument(entry.substr(equals + 1));
    if (!paths) return Error{where + ": " + paths.error().message};
    Result<LoadedMotion> loaded = load_motion(paths.value(), load_options);
    if (!loaded) return Error{where + ": " + loaded.error().message};
    const DuetTake& source = library.takes()[static_cast<std::size_t>(take)];
    const Clip& template_clip = source.template_motion.clip;
    if (std::optional<std::string> rates = rate_disagreement(loaded.value().clip, template_clip)) {
      return Error{where + ": " + *rates};
    }
    Result<Performance> performance =
        recorded_performance(std::move(loaded.value().clip), loaded.value().roles, take,
                             template_clip.frame_count(), template_clip.frame_rate());
    if (!performance) return Error{where + ": " + performance.error().message};
    EvalCase recorded;
    recorded.name = "recorded-" + source.name;
    recorded.description = "take " + source.name + " recorded in " + loaded.value().description;
    recorded.recipe.recorded = std::make_shared<const Performance>(std::move(performance).value());
    cases.push_back(std::move(recorded));
  }
  return cases;
}

}  // namespace duet::app
