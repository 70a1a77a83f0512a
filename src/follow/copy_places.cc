#include "duet/follow/copy_places.h"

#include <algorithm>
#include <string>

#include "duet/follow/template_model.h"

namespace duet {

Result<CopyPlaces> CopyPlaces::build(const TemplateModel& model, int captured_takes,
                                     std::span<const SyntheticTakeSource> sources) {
  auto fail = [](const std::string& what) { return make_error("copy places", 0, what); };
  if (captured_takes < 1 || captured_takes > model.num_takes()) {
    return fail("the model has " + std::to_string(model.num_takes()) + " takes, not " +
                std::to_string(captured_takes) + " captured ones");
  }
  if (static_cast<std::size_t>(model.num_takes() - captured_takes) != sources.size()) {
    return fail(std::to_string(model.num_takes() - captured_takes) + " copies in the model, " +
                std::to_string(sources.size()) + " sources");
  }
  CopyPlaces places;
  for (int take = 0; take <= captured_takes; ++take) {
    places.take_start_.push_back(take < captured_takes ? model.take_begin(take)
                                                       : model.take_end(captured_takes - 1));
  }
  const int captured_states = places.take_start_.back();
  places.place_.resize(static_cast<std::size_t>(model.num_states()));
  for (int take = 0; take < model.num_takes(); ++take) {
    for (int state = model.take_begin(take); state < model.take_end(take); ++state) {
      const int frame = state - model.take_begin(take);
      int place = state;
      if (take >= captured_takes) {
        const SyntheticTakeSource& source =
            sources[static_cast<std::size_t>(take - captured_takes)];
        if (source.real_take < 0 || source.real_take >= captured_takes) {
          return fail("take " + std::to_string(take) + " copies take " +
                      std::to_string(source.real_take) + ", which is not a captured take");
        }
        const int length = places.take_start_[static_cast<std::size_t>(source.real_take) + 1] -
                           places.take_start_[static_cast<std::size_t>(source.real_take)];
        place = places.take_start_[static_cast<std::size_t>(source.real_take)] +
                std::min(source.real_frame(frame), length - 1);
      }
      places.place_[static_cast<std::size_t>(state)] = place;
    }
  }
  // Group the states by place (a counting sort: states ascend within each place).
  places.copy_offsets_.assign(static_cast<std::size_t>(captured_states) + 1, 0);
  for (const int place : places.place_) ++places.copy_offsets_[static_cast<std::size_t>(place) + 1];
  for (std::size_t c = 1; c < places.copy_offsets_.size(); ++c) {
    places.copy_offsets_[c] += places.copy_offsets_[c - 1];
  }
  places.copies_.resize(places.place_.size());
  std::vector<int> next(places.copy_offsets_.begin(), places.copy_offsets_.end() - 1);
  for (int state = 0; state < model.num_states(); ++state) {
    const auto place = static_cast<std::size_t>(places.place_[static_cast<std::size_t>(state)]);
    places.copies_[static_cast<std::size_t>(next[place]++)] = state;
  }
  return places;
}

std::pair<int, int> CopyPlaces::window_of(int state, int window) const noexcept {
  const int place = place_of(state);
  // The captured take holding place: the last take start at or before it.
  const auto next = std::upper_bound(take_start_.begin(), take_start_.end() - 1, place);
  return {std::max(*(next - 1), place - window), std::min(*next, place + window + 1)};
}

float CopyPlaces::window_mass(const float* posterior, int state, int window) const noexcept {
  const auto [begin, end] = window_of(state, window);
  float mass = 0.0f;
  for (int k = copy_offsets_[static_cast<std::size_t>(begin)];
       k < copy_offsets_[static_cast<std::size_t>(end)]; ++k) {
    mass += posterior[copies_[static_cast<std::size_t>(k)]];
  }
  return mass;
}

float CopyPlaces::window_mass(const float* posterior, int state, int window,
                              std::span<const int> support) const noexcept {
  const auto [begin, end] = window_of(state, window);
  float mass = 0.0f;
  for (const int s : support) {
    const int p = place_of(s);
    if (p >= begin && p < end) mass += posterior[s];
  }
  return mass;
}

}  // namespace duet
