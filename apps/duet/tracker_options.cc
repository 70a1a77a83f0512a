#include "tracker_options.h"

#include "duet/follow/beam_follower.h"
#include "duet/follow/hmm_follower.h"
#include "duet/follow/naive_hmm.h"
#include "duet/follow/nearest_neighbour.h"
#include "duet/follow/online_dtw.h"
#include "number_checks.h"

namespace duet::app {

namespace {

template <typename T>
Result<std::unique_ptr<Tracker>> boxed(Result<T> tracker) {
  if (!tracker) return tracker.error();
  return std::unique_ptr<Tracker>(std::make_unique<T>(std::move(tracker).value()));
}

}  // namespace

void add_tracker_options(CLI::App& app, TrackerArgs& args) {
  app.add_option("--tracker", args.kind,
                 "Follower: hmm (the jump HMM, default), left-to-right (no jump), nearest "
                 "(per-frame nearest neighbour), dtw (online DTW), naive (the O(M^2) forward of "
                 "eq. 10; at most 8192 states)")
      ->check(CLI::IsMember({"hmm", "left-to-right", "nearest", "dtw", "naive"}));
  app.add_option("--preset", args.preset,
                 "HMM probabilities: default (chosen by measurement) or paper (Mousas 2018)")
      ->check(CLI::IsMember({"default", "paper"}));
  app.add_option("--sigma", args.sigma, "Emission sigma (standardised feature units)")
      ->check(positive_check());
  app.add_flag("--fixed-band", args.fixed_band,
               "Keep the HMM's band at the template's tempo instead of centring it on the "
               "dancer's tempo (the paper preset always keeps it fixed)");
  app.add_flag("--beam", args.beam,
               "Beam mode of the hmm tracker: emissions only for the states "
               "that carry mass and the jump candidates nearest the input, with a full step when "
               "the beam may have lost the dancer (docs/follower.md \"Beam mode\")");
}

Result<std::unique_ptr<Tracker>> make_tracker(const TrackerArgs& args, const DuetLibrary& library) {
  const TemplateModel& model = library.model();
  FollowParams params =
      follow_params_for(library.options().features.input_points,
                        args.preset == "paper" ? FollowParams::paper() : FollowParams{});
  if (args.sigma) params.emission_sigma = *args.sigma;
  if (args.fixed_band) params.tempo_adaptive = false;
  if (args.beam && args.kind != "hmm") {
    return make_error("--beam", 0, "beam mode is for the hmm tracker, not '" + args.kind + "'");
  }
  if (args.kind == "nearest") return boxed(NearestNeighbourTracker::create(model, params));
  if (args.kind == "dtw") return boxed(OnlineDtwTracker::create(model, OnlineDtwParams{}));
  if (args.kind == "naive") return boxed(NaiveHmmFollower::create(model, params));
  if (args.kind == "left-to-right") params.jump_enabled = false;
  if (args.beam && library.candidate_index()) {
    return boxed(BeamFollower::create(model, params, BeamParams::suited_to(params),
                                      library.candidate_index()));
  }
  if (args.beam) return boxed(BeamFollower::create(model, params, BeamParams::suited_to(params)));
  return boxed(HmmFollower::create(model, params));
}

}  // namespace duet::app
