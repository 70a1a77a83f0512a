// The evaluation runner (method.md 7): synthetic performances from real takes x followers, scored
// against ground truth. Builds nothing itself: the caller loads the duet libraries once per role
// and the runner runs one FollowSession per performance and tracker.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "duet/base/result.h"
#include "duet/eval/metrics.h"
#include "duet/eval/partner_metrics.h"
#include "duet/eval/partner_run.h"
#include "duet/eval/performance.h"
#include "duet/features/posture_bias.h"
#include "duet/follow/follow_params.h"
#include "duet/follow/online_dtw.h"
#include "duet/follow/tracker.h"
#include "duet/live/duet_library.h"

namespace duet {

// One way of performing a take (see docs/evaluation.md for the list).
struct EvalCase {
  std::string name;
  std::string description;
  PerformanceRecipe recipe;
  bool partner_role = false;  // the user dances the partner: the library is built with role=partner
  bool across_takes = false;  // improvisation draws segments from every take of the library
  // The name its random choices are seeded from (empty: `name`). A case delivered on another rig
  // ("improv@asf") keeps its base case's, so both rigs dance the very same performance.
  std::string seed_name;
  const std::string& seed_key() const { return seed_name.empty() ? name : seed_name; }
};

// Every case delivered on every rig: the library's own rig keeps the case as it is (rig null);
// another rig gives "<case>@<rig name>" with the rig in its recipe.
struct EvalRig {
  std::string name;                         // "native", "asf", "bandai", ...
  std::shared_ptr<const Skeleton> skeleton;  // metres; null = the library's own rig
  JointRoles roles;
};
std::vector<EvalCase> cases_on_rigs(const std::vector<EvalCase>& cases,
                                    const std::vector<EvalRig>& rigs);

// Magnitudes shared by the standard cases, so a run can make them harsher or gentler.
struct CaseSettings {
  double noise_rotation_deg = 3.0;  // RMS angle per joint per frame
  double noise_position_m = 0.01;   // per axis, root position
  double low_rate_hz = 30.0;
  double body_scale = 1.15;
  double improvise_duration_s = 0.0;  // 0 = the performed take's duration
  double suit_bias_deg = 5.0;         // suit-drift: calibration error per joint, RMS angle
  double suit_drift_deg = 5.0;        // suit-drift: drift per joint, RMS angle (10 s time constant)
  double tilt_deg = 12.0;             // tilted: how far the sensor's world is tilted
};

// The standard cases, in report order: clean, tempo-slow, tempo-fast, drift, improv,
// improv-pause, improv-library, noise, 30hz-noisy, late-frames, body-size, room-place,
// partner-role, improv-30hz-noisy, harsh (issue 11's sensor: fixed magnitudes, not the settings),
// 120hz-noisy (a sensor faster than the template, with the noise), 240hz-slow (a 240 Hz sensor
// with the noise, the dancer at 0.7x: a learner on a fast suit), dropouts (the noise, and
// tracking lost for 0.3-1 s every 8 s on average), suit-drift (an inertial suit: the noise, and
// every joint off by a calibration error and a slow drift), tilted (the noise, in a world tilted as
// a pitched camera sees it; levelled as a loaded file is), occluded (the noise, and one arm held
// where last seen for 0.3-1.5 s every 6 s on average).
std::vector<EvalCase> standard_cases(const CaseSettings& settings = {});

// The noise sweep (`duet eval --noise-sweep`): noise-sweep-0 ... noise-sweep-5, improv-pause at
// the take's rate with 0 to 5 degrees of rotation noise per axis (and 1 cm of root noise above 0).
std::vector<EvalCase> noise_sweep_cases();

// The suit sweep (`duet eval --suit-sweep`): suit-sweep-0, -2, ... -10, the suit-drift case (the
// whole take, the settings' white noise) with 0 to 10 degrees of calibration error and as much
// drift per joint: how far off a suit may be before the follower loses the dance.
std::vector<EvalCase> suit_sweep_cases(const CaseSettings& settings = {});

// The body sweep (`duet eval --body-sweep`): body-sweep-80, -90, ... -120, improv-pause at the
// take's rate with the settings' noise, danced by a body 0.8x to 1.2x the template dancer's
// (skeleton and root path scaled): issue 10's users of other sizes, jumps and held hands included.
std::vector<EvalCase> body_sweep_cases(const CaseSettings& settings = {});

// The rate sweep (`duet eval --rate-sweep`): rate-sweep-20, -25, -30, -50, -60, -72, -90, -120,
// -240, improv-pause with the settings' noise from a sensor at that rate: a phone's pose
// estimator, video, VR headsets, inertial suits (the salsa's own rate is 60 Hz).
std::vector<EvalCase> rate_sweep_cases(const CaseSettings& settings = {});

// The tempo sweep (`duet eval --tempo-sweep`): tempo-sweep-50, -60, -70, -85, -100, -120, -140,
// -160, improv-pause with the settings' noise danced at 0.5x to 1.6x the capture's tempo: a
// learner at half tempo to a dancer well ahead of the music.
std::vector<EvalCase> tempo_sweep_cases(const CaseSettings& settings = {});

enum class TrackerKind {
  kHmm,               // the jump HMM with EvalOptions::hmm (the defaults unless tuned)
  kHmmPaper,          // FollowParams::paper() transitions, emission settings from EvalOptions::hmm
  kLeftToRight,       // EvalOptions::hmm without the jump
  kNearestNeighbour,  // per-frame nearest neighbour
  kOnlineDtw,         // windowed online DTW
  kNaiveHmm,          // the O(M^2) forward: only on a one-take library, compared with kHmm
};
std::string_view tracker_kind_name(TrackerKind kind);  // "hmm", "hmm-paper", ...
bool parse_tracker_kind(std::string_view name, TrackerKind& kind);
std::vector<TrackerKind> all_tracker_kinds();

struct EvalOptions {
  std::vector<int> takes;  // library indices of the takes to perform from
  std::vector<EvalCase> cases;
  std::vector<TrackerKind> trackers;
  std::uint64_t seed = 1;
  FollowParams hmm;     // parameters of the "hmm" tracker (defaults + tuning)
  bool beam = false;    // the hmm and hmm-paper trackers in beam mode (BeamFollower)
  OnlineDtwParams dtw;  // its emission sigma and lost threshold are taken from hmm
  MetricsOptions metrics;
  // Keep per-frame traces of this case on the first performed take (for plots); empty = none.
  std::string trace_case;
  // The case the naive O(M^2) forward is compared on (when kNaiveHmm is among the trackers); if
  // it is not run or not performed from one take in the user's role, the first case that is.
  std::string naive_case = "improv-pause";
  // Partner metrics (docs/evaluation.md "Partner metrics"): every case x take also runs the live
  // loop with the "hmm" tracker once per partner_configs entry and scores the synthesized partner.
  bool partner_metrics = false;
  std::vector<PartnerConfig> partner_configs = standard_partner_configs();
  PartnerMetricsOptions partner;
  // Keep every scored frame's estimate and error in EvalRow::frames (for --frames-csv: fitting
  // and checking the confidence calibration and the lost decision offline).
  bool keep_frames = false;
  // Whether a lost frame's confidence goes through LostConfidence (PostureBiasParams::
  // lost_confidence); false gives scripts/fit_lost_confidence.py the confidence before it.
  bool lost_confidence = true;
};

// One scored (not pause) frame of a performance, when EvalOptions::keep_frames.
struct ScoredFrame {
  int take = 0;
  double error_ms = 0.0;  // frame_error_ms
  FrameEstimate estimate;
  TruthFrame truth;  // where the dancer really was
};

// A case x tracker, pooled over the performed takes, and per take.
struct EvalRow {
  std::string case_name;
  std::string tracker;
  Metrics metrics;
  std::vector<std::pair<int, Metrics>> per_take;  // (take index, metrics)
  std::vector<ScoredFrame> frames;                // when EvalOptions::keep_frames
};

// A case x configuration of the corrections, pooled over the performed takes, and per take.
struct PartnerRow {
  std::string case_name;
  std::string config;
  bool aligned = true;  // align was on: joint and hand errors are in the user's frame
  PartnerMetrics metrics;
  std::vector<std::pair<int, PartnerMetrics>> per_take;
  double loop_step_us = 0.0;  // mean LiveLoop::step with the real tracker (same for the case)
};

struct EvalTrace {
  std::string case_name;
  std::string tracker;
  int take = 0;  // the performed take
  double template_rate_hz = 0.0;
  std::vector<double> times_s;
  std::vector<TruthFrame> truth;
  std::vector<FrameEstimate> estimates;
};

// The naive O(M^2) forward against the O(M) HMM on a one-take library (the first performed take
// alone; features standardised as in the full library), same parameters, same input.
struct NaiveCheck {
  bool ran = false;
  int take = 0;
  std::string take_name;
  std::string case_name;
  int states = 0;
  long long frames = 0;
  long long same_state = 0;  // frames where both estimates agree
  Metrics naive;             // against the truth (the one-take library)
  Metrics fast;
};

struct EvalReport {
  std::vector<EvalRow> rows;
  std::vector<EvalTrace> traces;
  NaiveCheck naive;
  std::vector<PartnerRow> partner_rows;  // when EvalOptions::partner_metrics
  PartnerMetricsOptions partner_options;
  std::vector<std::string> take_names;  // of the library, by index
  int library_states = 0;
};

// done/total count performance x tracker runs; `what` names the current one.
using EvalProgress = std::function<void(long long done, long long total, const std::string& what)>;

// library: the user's role as given; partner_library: built with role=partner, needed only by
// partner_role cases (may be the same object as library, or null when no such case runs). Both
// must hold the same takes in the same order. Errors: bad take indices, a missing partner library,
// a tracker that cannot be built, a performance that cannot be made or followed.
Result<EvalReport> run_evaluation(const DuetLibrary& library, const DuetLibrary* partner_library,
                                  const EvalOptions& options, const EvalProgress& progress = {});

// Runs one tracker over one performance through a FollowSession, timing every step.
Result<std::vector<FrameEstimate>> follow_performance(const DuetLibrary& library,
                                                      const Performance& performance,
                                                      std::unique_ptr<Tracker> tracker,
                                                      const PostureBiasParams& bias = {});

// The tracker of a kind on a model (kNaiveHmm is built too, but only fits small models). index:
// the beam's jump candidate index for this model when one exists (DuetLibrary::candidate_index);
// else the beam builds its own.
Result<std::unique_ptr<Tracker>> make_eval_tracker(
    TrackerKind kind, const TemplateModel& model, const EvalOptions& options,
    std::shared_ptr<const JumpCandidateIndex> index = nullptr);

}  // namespace duet
