#include "duet/follow/synthetic_library.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace duet {
namespace {

// One take of the synthetic library: its source and its length in frames.
struct PlannedTake {
  SyntheticTakeSource source;
  int frames = 0;
};

// The takes, in order. The speeds come from their own random stream (the noise from another), so
// the plan is the same whether or not the features are built.
Result<std::vector<PlannedTake>> plan_takes(const TemplateModel& real,
                                            const SyntheticLibraryOptions& options) {
  if (options.num_states < 3) return make_error("synthetic library", 0, "num_states must be >= 3");
  if (!(options.min_speed > 0.0f && options.min_speed <= options.max_speed &&
        std::isfinite(options.max_speed))) {
    return make_error("synthetic library", 0, "speeds must satisfy 0 < min_speed <= max_speed");
  }
  if (!(options.noise >= 0.0f && std::isfinite(options.noise))) {
    return make_error("synthetic library", 0, "noise must be >= 0");
  }
  if (!options.mirror.empty()) {
    if (static_cast<int>(options.mirror.size()) != real.num_dims()) {
      return make_error("synthetic library", 0,
                        "the mirror map has " + std::to_string(options.mirror.size()) +
                            " dimensions, the library " + std::to_string(real.num_dims()));
    }
    for (const MirroredDim& m : options.mirror) {
      if (m.source < 0 || m.source >= real.num_dims() || !std::isfinite(m.scale) ||
          !std::isfinite(m.offset)) {
        return make_error("synthetic library", 0, "the mirror map is not valid for this library");
      }
    }
  }
  if (options.keep_real_takes && options.num_states < real.num_states()) {
    return make_error("synthetic library", 0,
                      "num_states (" + std::to_string(options.num_states) +
                          ") is below the real library's " + std::to_string(real.num_states()) +
                          " states, which it keeps");
  }
  std::mt19937 rng(options.seed);
  std::uniform_real_distribution<float> speed_of(options.min_speed, options.max_speed);
  std::vector<PlannedTake> plan;
  int states = 0;
  if (options.keep_real_takes) {
    for (int take = 0; take < real.num_takes(); ++take) {
      const int length = real.take_end(take) - real.take_begin(take);
      plan.push_back({{take, 1.0f, length, false}, length});
      states += length;
    }
  }
  for (int copy = 0; states < options.num_states; ++copy) {
    const int take = copy % real.num_takes();
    const int length = real.take_end(take) - real.take_begin(take);
    const float speed = speed_of(rng);
    int frames =
        std::max(1, static_cast<int>(std::floor(static_cast<float>(length - 1) / speed)) + 1);
    frames = std::min(frames, options.num_states - states);
    if (frames < 3 && !plan.empty()) {
      // Too short to be a take: the previous take ends here instead (its last frame repeated).
      plan.back().frames += options.num_states - states;
      break;
    }
    const bool mirrored = !options.mirror.empty() && copy % 2 == 1;
    plan.push_back({{take, speed, length, mirrored}, frames});
    states += frames;
  }
  return plan;
}

}  // namespace

int SyntheticTakeSource::real_frame(int frame) const noexcept {
  const float position = static_cast<float>(std::max(frame, 0)) * speed;
  return std::clamp(static_cast<int>(std::lround(position)), 0, std::max(real_length - 1, 0));
}

Result<TemplateModel> synthesize_library(const TemplateModel& real,
                                         const SyntheticLibraryOptions& options) {
  Result<std::vector<PlannedTake>> plan = plan_takes(real, options);
  if (!plan) return plan.error();
  const int dims = real.num_dims();
  const int posture = dims - real.velocity_dims();
  std::mt19937 rng(options.seed ^ 0x9e3779b9u);
  std::normal_distribution<float> noise(0.0f, std::max(options.noise, 1e-30f));
  const bool noisy = options.noise > 0.0f;

  std::vector<float> unmirrored(static_cast<std::size_t>(dims));
  FeatureMatrix out(options.num_states, dims);
  std::vector<int> starts;
  int row = 0;
  for (const PlannedTake& planned : plan.value()) {
    const SyntheticTakeSource& source = planned.source;
    const int begin = real.take_begin(source.real_take);
    const int length = source.real_length;
    const bool copy = !(options.keep_real_takes &&
                        static_cast<int>(starts.size()) < real.num_takes());
    starts.push_back(row);
    for (int t = 0; t < planned.frames; ++t, ++row) {
      const float position =
          std::min(static_cast<float>(t) * source.speed, static_cast<float>(length - 1));
      const int i0 = static_cast<int>(position);
      const int i1 = std::min(i0 + 1, length - 1);
      const float w = position - static_cast<float>(i0);
      for (int d = 0; d < dims; ++d) {
        unmirrored[static_cast<std::size_t>(d)] =
            (1.0f - w) * real.features()(begin + i0, d) + w * real.features()(begin + i1, d);
      }
      for (int d = 0; d < dims; ++d) {
        float value = unmirrored[static_cast<std::size_t>(d)];
        if (source.mirrored) {
          const MirroredDim& m = options.mirror[static_cast<std::size_t>(d)];
          value = m.scale * unmirrored[static_cast<std::size_t>(m.source)] + m.offset;
        }
        if (!copy) {
          out(row, d) = value;
          continue;
        }
        if (d >= posture) value *= source.speed;  // velocities scale with the speed
        out(row, d) = noisy ? value + noise(rng) : value;
      }
    }
  }
  Result<TemplateModel> model = TemplateModel::build(std::move(out), std::move(starts),
                                                     real.frame_rate_hz(), real.velocity_dims());
  if (!model) return model.error();
  if (Status limbs = model.value().set_limbs(real.limbs()); !limbs) return limbs.error();
  return model;
}

Result<std::vector<SyntheticTakeSource>> synthetic_take_sources(
    const TemplateModel& real, const SyntheticLibraryOptions& options) {
  Result<std::vector<PlannedTake>> plan = plan_takes(real, options);
  if (!plan) return plan.error();
  std::vector<SyntheticTakeSource> sources;
  sources.reserve(plan.value().size());
  for (const PlannedTake& planned : plan.value()) sources.push_back(planned.source);
  return sources;
}

}  // namespace duet
