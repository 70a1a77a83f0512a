#include "tracker_options.h"

#include "duet/follow/hmm_follower.h"

namespace duet::app {

void add_tracker_options(CLI::App& app, TrackerArgs& args) {
  app.add_option("--tracker", args.kind,
                 "Follower: hmm (the jump HMM, default) or left-to-right (no jump)")
      ->check(CLI::IsMember({"hmm", "left-to-right"}));
  app.add_option("--preset", args.preset,
                 "HMM probabilities: default (chosen by measurement) or paper (Mousas 2018)")
      ->check(CLI::IsMember({"default", "paper"}));
  app.add_option("--sigma", args.sigma, "Emission sigma (standardised feature units)")
      ->check(CLI::PositiveNumber);
}

Result<std::unique_ptr<Tracker>> make_tracker(const TrackerArgs& args,
                                              const TemplateModel& model) {
  FollowParams params = args.preset == "paper" ? FollowParams::paper() : FollowParams{};
  if (args.kind == "left-to-right") params.jump_enabled = false;
  if (args.sigma) params.emission_sigma = *args.sigma;
  Result<HmmFollower> follower = HmmFollower::create(model, params);
  if (!follower) return follower.error();
  return std::unique_ptr<Tracker>(std::make_unique<HmmFollower>(std::move(follower).value()));
}

}  // namespace duet::app
