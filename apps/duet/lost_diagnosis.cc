#include "lost_diagnosis.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace duet::app {

LostSummary summarise_lost(std::span<const FollowResult> results) {
  LostSummary summary;
  for (const FollowResult& r : results) {
    summary.held_still += r.held_still ? 1 : 0;
    summary.lost_unseen += r.lost && r.missing ? 1 : 0;
    ++summary.frames;
    summary.lost += r.lost ? 1 : 0;
    summary.jumps += r.jumped ? 1 : 0;
    summary.missing += r.missing ? 1 : 0;
    summary.outliers += r.outlier ? 1 : 0;
    summary.partly_observed += r.partly_observed ? 1 : 0;
  }
  return summary;
}

std::string describe_set_aside(const LostSummary& summary) {
  if (summary.missing == 0 && summary.outliers == 0 && summary.partly_observed == 0) return "";
  const std::string unseen_hand =
      summary.partly_observed > 0
          ? fmt::format("; {} with a hand unseen, its controller repeating its last pose",
                        summary.partly_observed)
          : "";
  return fmt::format(" (frames without evidence: {} missing or repeated, {} outliers set aside{})",
                     summary.missing, summary.outliers, unseen_hand);
}

float median_followed_tempo(std::span<const FollowResult> results) {
  std::vector<float> followed;
  std::vector<float> all;
  for (const FollowResult& r : results) {
    if (r.held_still) continue;  // a dancer standing still says nothing of the input's clock
    all.push_back(r.tempo);
    if (!r.lost) followed.push_back(r.tempo);
  }
  std::vector<float>& tempos = 10 * followed.size() >= all.size() ? followed : all;
  if (tempos.empty()) return 1.0f;
  const auto middle = tempos.begin() + static_cast<std::ptrdiff_t>(tempos.size() / 2);
  std::ranges::nth_element(tempos, middle);
  return *middle;
}

std::optional<std::string> rate_mismatch(double input_rate_hz, double library_rate_hz,
                                         float median_tempo) {
  if (median_tempo >= kSlowestDancerTempo && median_tempo <= kFastestDancerTempo) {
    return std::nullopt;
  }
  // The rate at which the input would move at the library's tempo (a 60 Hz take read at 120 fps
  // moves at 2x), snapped to a capture rate.
  double rate = input_rate_hz / median_tempo;
  constexpr std::array<double, 10> kCommonRates{24, 25, 30, 48, 50, 60, 90, 100, 120, 240};
  for (const double common : kCommonRates) {
    if (std::abs(rate - common) <= 0.1 * common) {
      rate = common;
      break;
    }
  }
  return fmt::format(
      "rate: the input was read at {:g} fps but moves {:.2f}x as fast as the library ({:g} fps); "
      "if its header is wrong, pass --input-fps {:.0f}",
      input_rate_hz, median_tempo, library_rate_hz, rate);
}

std::vector<std::string> diagnose_lost(const LostSummary& summary, const LostContext& context) {
  std::vector<std::string> causes;
  // The role: the same input followed as the other dancer.
  if (context.other_role_lost_fraction &&
      *context.other_role_lost_fraction < 0.5 * summary.lost_fraction()) {
    const DancerRole other =
        context.role == DancerRole::kLeader ? DancerRole::kPartner : DancerRole::kLeader;
    causes.push_back(fmt::format(
        "role: followed as the {} instead, {:.0f}% of frames are lost (against {:.0f}%): the input "
        "dances the {}'s part — pass --role {}, or check the order of each --pair (LEADER then "
        "PARTNER)",
        dancer_role_name(other), 100.0 * *context.other_role_lost_fraction,
        100.0 * summary.lost_fraction(), dancer_role_name(other), dancer_role_name(other)));
  }
  // The rate: the follower's tempo far from 1 means the input's clock runs at another speed.
  if (std::optional<std::string> rate =
          rate_mismatch(context.input_rate_hz, context.library_rate_hz, context.median_tempo)) {
    causes.push_back(std::move(*rate));
  }
  if (context.input != nullptr) {
    const LoadedMotion& input = *context.input;
    // The units: an implausible body height.
    const double height = input.body.standing_height_m;
    if (!input.units_warning.empty() || (input.body.valid() && (height < 1.2 || height > 2.2))) {
      causes.push_back(fmt::format(
          "units: the dancer is {:.2f} m tall at {} ({}){}; pass --input-scale with the file's "
          "metres per unit",
          height,
          input.units_name.empty() ? fmt::format("{:g} m per unit", input.metres_per_unit)
                                   : input.units_name,
          input.units_source, input.units_warning.empty() ? "" : " — " + input.units_warning));
    }
    // The up axis: the body could not tell it, or it was given.
    if (!input.up_warning.empty()) {
      causes.push_back(
          fmt::format("up axis: {}; if the file is Z-up, pass --input-up z", input.up_warning));
    } else if (input.up_source == kUpAxisGiven) {
      causes.push_back(fmt::format(
          "up axis: {} was given (--input-up); `duet inspect {}` reads it from the body",
          up_axis_name(input.up_axis), input.description));
    }
    // The rig: roles found without a known convention may be wrong.
    if (input.roles.convention == "names" || input.roles.convention == "hierarchy") {
      causes.push_back(fmt::format(
          "rig: the body roles of {} were found from its joint {} — check them with `duet "
          "inspect {}` and give a skeleton map with --input-map if one is wrong",
          input.description, input.roles.convention == "names" ? "names" : "hierarchy",
          input.description));
    }
  }
  if (std::abs(context.input_rate_hz - context.library_rate_hz) > 1e-6 &&
      !rate_mismatch(context.input_rate_hz, context.library_rate_hz, context.median_tempo)) {
    causes.push_back(fmt::format(
        "rate: the input runs at {:g} fps and the library at {:g} fps (fine if both are right)",
        context.input_rate_hz, context.library_rate_hz));
  }
  // Stretches that account for a tenth of the lost frames or more are named, with their seconds.
  const auto explains_lost = [&](int frames) { return frames > 0 && 10 * frames >= summary.lost; };
  const auto seconds = [&](int frames) {
    return context.input_rate_hz > 0.0 ? frames / context.input_rate_hz : 0.0;
  };
  // Standing still: a dance moves on, so seconds held at one place are lost (HeldPlace).
  if (explains_lost(summary.held_still)) {
    causes.push_back(fmt::format(
        "still: {:.1f} s of the input held one place of the dance for seconds at a time (the "
        "dancer standing still: lost, since a dance moves on); trim the waiting from the "
        "recording, or pass --allow-lost",
        seconds(summary.held_still)));
  }
  // Stalled: no new pose for seconds (a sensor that stopped updating, poses without numbers).
  if (explains_lost(summary.lost_unseen)) {
    causes.push_back(fmt::format(
        "stalled: {:.1f} s of the input brought no new pose for seconds at a time (the same pose "
        "sent again, or none: a sensor or stream that stopped updating); cut those stretches, or "
        "pass --allow-lost",
        seconds(summary.lost_unseen)));
  }
  causes.push_back(
      "dance: the input may not be any part of the library's dance (another dance, a walk, a "
      "wave: then lost is the right answer; pass --allow-lost to keep exit 0)");
  return causes;
}

}  // namespace duet::app
