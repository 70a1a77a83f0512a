#include "duet/follow/synthetic_library.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace duet {

Result<TemplateModel> synthesize_library(const TemplateModel& real,
                                         const SyntheticLibraryOptions& options) {
  auto fail = [](const std::string& what) { return make_error("synthetic library", 0, what); };
  if (options.num_states < 3) return fail("num_states must be >= 3");
  if (!(options.min_speed > 0.0f && options.min_speed <= options.max_speed &&
        std::isfinite(options.max_speed))) {
    return fail("speeds must satisfy 0 < min_speed <= max_speed");
  }
  if (!(options.noise >= 0.0f && std::isfinite(options.noise))) return fail("noise must be >= 0");

  const int dims = real.num_dims();
  const int posture = dims - real.velocity_dims();
  std::mt19937 rng(options.seed);
  std::uniform_real_distribution<float> speed_of(options.min_speed, options.max_speed);
  std::normal_distribution<float> noise(0.0f, std::max(options.noise, 1e-30f));
  const bool noisy = options.noise > 0.0f;

  FeatureMatrix out(options.num_states, dims);
  std::vector<int> starts;
  int row = 0;
  for (int copy = 0; row < options.num_states; ++copy) {
    const int take = copy % real.num_takes();
    const int begin = real.take_begin(take);
    const int length = real.take_end(take) - begin;
    const float speed = speed_of(rng);
    int frames = std::max(1, static_cast<int>(std::floor(static_cast<float>(length - 1) / speed)) + 1);
    frames = std::min(frames, options.num_states - row);
    if (frames < 3 && !starts.empty()) {
      // Too short to be a take: the previous copy ends here instead (its last frame repeated).
      for (; row < options.num_states; ++row) out.row(row) = out.row(row - 1);
      break;
    }
    starts.push_back(row);
    for (int t = 0; t < frames; ++t, ++row) {
      const float position = std::min(static_cast<float>(t) * speed, static_cast<float>(length - 1));
      const int i0 = static_cast<int>(position);
      const int i1 = std::min(i0 + 1, length - 1);
      const float w = position - static_cast<float>(i0);
      for (int d = 0; d < dims; ++d) {
        float value = (1.0f - w) * real.features()(begin + i0, d) + w * real.features()(begin + i1, d);
        if (d >= posture) value *= speed;  // velocities scale with the speed
        out(row, d) = noisy ? value + noise(rng) : value;
      }
    }
  }
  return TemplateModel::build(std::move(out), std::move(starts), real.frame_rate_hz(),
                              real.velocity_dims());
}

}  // namespace duet
