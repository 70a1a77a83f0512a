#include "duet/eval/report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <string_view>

namespace duet {

namespace {

std::string percent(double fraction) { return fmt::format("{:.1f}%", 100.0 * fraction); }

std::string recovery_text(const Metrics& m) {
  if (m.jumps == 0) return "-";
  if (std::isinf(m.median_recovery_s)) return "none";
  return fmt::format("{:.2f}", m.median_recovery_s);
}

// The median time to find the dance (Metrics::median_find_s).
std::string find_text(const Metrics& m) {
  if (std::isinf(m.median_find_s)) return "never";
  return fmt::format("{:.2f}", m.median_find_s);
}

std::string number_or_empty(double value, int decimals) {
  if (std::isinf(value)) return "inf";
  return fmt::format("{:.{}f}", value, decimals);
}

void append_csv_row(std::string& out, const std::string& case_name, const std::string& tracker,
                    const std::string& take, const std::string& take_name, const Metrics& m) {
  fmt::format_to(
      std::back_inserter(out),
      "{},{},{},{},{},{},{},{:.5f},{:.5f},{:.5f},{:.5f},{:.2f},{:.2f},{},{},{},{},{:.5f},"
      "{:.2f},{},{},{:.3f},{:.5f},{:.5f},{:.3f},{:.5f},{},{},{:.5f}\n",
      case_name, tracker, take, take_name, m.frames, m.scored_frames, m.pause_frames, m.within_50ms,
      m.within_100ms, m.within_300ms, m.miss_fraction, m.mean_error_ms, m.median_error_ms, m.jumps,
      m.recovered_jumps, m.jumps ? number_or_empty(m.median_recovery_s, 4) : "",
      m.recovered_jumps ? number_or_empty(m.mean_recovery_s, 4) : "", m.lost_fraction,
      m.mean_step_us, m.reported_jumps, m.false_jumps, m.false_jumps_per_minute,
      m.lost_on_tracked_fraction, m.confidence_ece, m.lost_switches_per_minute,
      m.within_100ms_alike, number_or_empty(m.median_find_s, 3), number_or_empty(m.worst_find_s, 3),
      m.within_100ms_found);
}

std::string take_name(const EvalReport& report, int take) {
  return take >= 0 && take < static_cast<int>(report.take_names.size())
             ? report.take_names[static_cast<std::size_t>(take)]
             : std::to_string(take);
}

std::string partner_cell(bool meaningful, double value, int decimals) {
  return meaningful ? fmt::format("{:.{}f}", value, decimals) : std::string("-");
}

// What each column of the partner table means, in the table's own words (docs/evaluation.md
// has the definitions in full).
void append_partner_legend(std::string& out, const PartnerMetricsOptions& options) {
  const double pct = 100.0 * options.reference_percentile;
  const double window = options.post_jump_window_s;
  out +=
      "\ncolumns (against the true response: the partner had the follower known the true frame):\n";
  const auto line = [&out](std::string_view name, const std::string& text) {
    fmt::format_to(std::back_inserter(out), "  {:<18} {}\n", name, text);
  };
  line("frames", "performance frames, pauses included");
  line("joint cm", "mean distance of every joint (End Sites included) from the true response's");
  line("hand med/avg cm",
       "while the take's dancers hold hands: |partner-to-user wrist distance - the captured "
       "one|, median / mean");
  line("hand n samples", "(frame, holding hand pair) samples behind hand med/avg");
  line("slip %", fmt::format("frames in which a toe within {:g} cm of the floor moves faster "
                             "than {:g} m/s horizontally",
                             100.0 * options.slip.height_margin_m, options.slip.speed_mps));
  line("skate cm/s", "mean horizontal speed of the toes near the floor");
  line("jump max/med deg/s",
       fmt::format("largest joint angular speed in the {:g} s after each true jump: largest / "
                   "median over jumps",
                   window));
  line("true med deg/s", "the same for the true response, median over jumps");
  line(">p99 jumps", fmt::format("jumps whose largest exceeds the captured response's p{:g} "
                                 "angular speed",
                                 pct));
  line(">true jumps", "of those, jumps whose largest also exceeds the true response's there");
  line(">win99 jumps", fmt::format("jumps whose largest exceeds the p{:g} of the captured "
                                   "response's largest per {:g} s window",
                                   pct, window));
  line(">w99&t jumps", "of those, jumps whose largest also exceeds the true response's there");
  line("jerk m/s^3",
       "mean |third derivative| of the joint positions; true jerk: the true "
       "response's");
  line("us/frame",
       "mean live-loop step with the tracker's estimates replayed (features, "
       "synthesis, forward kinematics)");
  line("-",
       "not meaningful: no jumps or hand contacts, or `none` (partner not placed at the "
       "user)");
}

std::string seconds_cell(double s) {
  return std::isfinite(s) ? fmt::format("{:.2f}", s) : std::string("never");
}

// Issue 11's partner targets, one line per case x configuration: is the partner as steady as the
// captured one, and how fast is it back after a jump.
void append_steadiness_table(std::string& out, const EvalReport& report) {
  const PartnerMetricsOptions& o = report.partner_options;
  out += "\npartner steadiness and transitions after jumps (issue 11; docs/evaluation.md):\n";
  constexpr const char* kHeader =
      "{:<18} {:<12} {:>8} {:>8} {:>6} {:>6} {:>8} {:>8} {:>7} {:>8} {:>8} {:>7} {:>8} {:>8} "
      "{:>8} {:>6} {:>8} {:>7} {:>7} {:>7} {:>7}\n";
  fmt::format_to(std::back_inserter(out), kHeader, "case", "corrections", "speed", "captured",
                 "ratio", "x true", "hand med", "sensed", ">win99", "rejoin", "rejoin", "in time",
                 "spacing", "spacing", "slide", ">limit", "slide", ">limit", "crowded", "closest",
                 "crowded");
  fmt::format_to(std::back_inserter(out), kHeader, "", "",
                 fmt::format("p{:g}", 100.0 * o.reference_percentile), "deg/s", "", "", "cm", "cm",
                 "jumps", "med s", "max s", "jumps", "med cm", "max cm", "jump m/s", "jumps",
                 "all m/s", "frames", "jumps", "cm", "frames");
  for (const PartnerRow& row : report.partner_rows) {
    const PartnerMetrics& m = row.metrics;
    const bool hands = row.aligned && m.hand_samples > 0;
    const bool jumps = m.jumps > 0;
    const bool placed = row.aligned && jumps;
    fmt::format_to(
        std::back_inserter(out), kHeader, row.case_name, row.config,
        fmt::format("{:.0f}", m.frame_speed_deg_s),
        fmt::format("{:.0f}", m.captured_frame_speed_deg_s),
        partner_cell(m.captured_frame_speed_deg_s > 0.0,
                     m.frame_speed_deg_s / std::max(m.captured_frame_speed_deg_s, 1e-9), 2),
        partner_cell(m.true_frame_speed_deg_s > 0.0,
                     m.frame_speed_deg_s / std::max(m.true_frame_speed_deg_s, 1e-9), 2),
        partner_cell(hands, m.median_hand_error_cm, 2),
        partner_cell(hands, m.median_sensed_hand_error_cm, 2),
        jumps ? fmt::format("{}/{}", m.jumps_over_window_reference, m.jumps) : "-",
        placed ? seconds_cell(m.median_rejoin_s) : "-", placed ? seconds_cell(m.max_rejoin_s) : "-",
        placed ? fmt::format("{}/{}", m.jumps_rejoined_in_time, m.jumps) : "-",
        partner_cell(placed, m.median_spacing_error_cm, 1),
        partner_cell(placed, m.max_spacing_error_cm, 1),
        partner_cell(jumps, m.max_jump_slide_mps, 2),
        jumps ? fmt::format("{}/{}", m.jumps_sliding, m.jumps) : "-",
        fmt::format("{:.2f}", m.max_slide_mps), m.sliding_frames,
        placed ? fmt::format("{}/{}", m.jumps_crowded, m.jumps) : "-",
        partner_cell(row.aligned && m.closest_cm >= 0.0, m.closest_cm, 0),
        row.aligned ? fmt::format("{}", m.crowded_frames) : "-");
  }
  out += "\ncolumns:\n";
  const auto line = [&out](std::string_view name, const std::string& text) {
    fmt::format_to(std::back_inserter(out), "  {:<18} {}\n", name, text);
  };
  line("speed, captured",
       fmt::format("p{:g} of the per-frame largest joint angular speed: the partner's, the "
                   "captured partner's over the same takes; ratio = speed / captured",
                   100.0 * o.reference_percentile));
  line("x true",
       "speed / the same percentile of the true response as the performance shows it "
       "(the captured partner at the true frames and the performance's timing: a "
       "faster dance asks a faster partner)");
  line("hand med, sensed",
       "median over contact frames of |partner wrist to user wrist - captured|, the user's real "
       "wrist (before the sensor's noise) and the wrist the sensor reports");
  line("rejoin s", fmt::format("after each true jump, until the held hands are within {:g} cm of "
                               "the captured grip and the spacing within {:g} cm of the true "
                               "response's, for {:g} s (never: not within {:g} s)",
                               100.0 * o.rejoin_tolerance_m, 100.0 * o.rejoin_tolerance_m,
                               o.rejoin_hold_s, o.rejoin_search_s));
  line("in time jumps", fmt::format("jumps rejoined within {:g} s", o.rejoin_deadline_s));
  line("spacing cm", fmt::format("|partner-to-user - true response-to-user pelvis distance| {:g} s "
                                 "after each jump",
                                 o.rejoin_deadline_s));
  line("slide m/s",
       fmt::format("largest speed of a toe on the floor whose true foot is planted: in the {:g} s "
                   "after a jump (largest over jumps; >limit: jumps above {:g} m/s), and over "
                   "every frame (>limit: frames above it)",
                   o.post_jump_window_s, o.slide_limit_mps));
  line("crowded, closest",
       fmt::format(
           "frames where the partner's pelvis is within {:g} cm of the user's (horizontally) "
           "while the true response's is at least {:g} cm away: jumps with such a frame "
           "in their {:g} s window, and all such frames; closest: the partner's smallest "
           "distance to the user where the true response keeps that {:g} cm",
           100.0 * o.crowd_distance_m, 100.0 * (o.crowd_distance_m + o.crowd_margin_m),
           o.post_jump_window_s, 100.0 * (o.crowd_distance_m + o.crowd_margin_m)));
}

// The partner section of the table: one line per case x configuration, then per case the captured
// partner's own numbers and the loop's cost with the tracker.
void append_partner_table(std::string& out, const EvalReport& report) {
  if (report.partner_rows.empty()) return;
  out +=
      "\npartner metrics (hmm tracker, the live loop as `duet follow` runs it; against the true "
      "response, docs/evaluation.md):\n";
  constexpr const char* kHeader =
      "{:<18} {:<12} {:>7} {:>8} {:>9} {:>9} {:>7} {:>7} {:>7} {:>9} {:>9} {:>9} {:>7} "
      "{:>7} {:>7} {:>7} {:>9} {:>9} {:>8}\n";
  // Two header lines: the column's name, then its unit (the legend below says what each means).
  fmt::format_to(std::back_inserter(out), kHeader, "case", "corrections", "frames", "joint",
                 "hand med", "hand avg", "hand n", "slip", "skate", "jump max", "jump med",
                 "true med", ">p99", ">true", ">win99", ">w99&t", "jerk", "true jerk", "us/frame");
  fmt::format_to(std::back_inserter(out), kHeader, "", "", "", "cm", "cm", "cm", "samples", "%",
                 "cm/s", "deg/s", "deg/s", "deg/s", "jumps", "jumps", "jumps", "jumps", "m/s^3",
                 "m/s^3", "us");
  std::string previous_case;
  const auto case_footer = [&](const PartnerRow& row) {
    const PartnerMetrics& m = row.metrics;
    fmt::format_to(std::back_inserter(out),
                   "  {}: captured partner slip {}, skate {:.1f} cm/s, p{:g} angular speed {:.0f} "
                   "deg/s (its own {:g} s "
                   "windows above it: {}; p{:g} of their largest per window: {:.0f} deg/s); loop "
                   "step with the tracker {:.0f} us/frame\n",
                   row.case_name, percent(m.captured_slip_rate), m.captured_ground_speed_cm_s,
                   100.0 * report.partner_options.reference_percentile, m.reference_speed_deg_s,
                   report.partner_options.post_jump_window_s,
                   percent(m.captured_windows_over_reference),
                   100.0 * report.partner_options.reference_percentile,
                   m.window_reference_speed_deg_s, row.loop_step_us);
  };
  for (std::size_t i = 0; i < report.partner_rows.size(); ++i) {
    const PartnerRow& row = report.partner_rows[i];
    if (!previous_case.empty() && row.case_name != previous_case) {
      case_footer(report.partner_rows[i - 1]);
      out += "\n";
    }
    previous_case = row.case_name;
    const PartnerMetrics& m = row.metrics;
    const bool hands = row.aligned && m.hand_samples > 0;
    fmt::format_to(std::back_inserter(out), kHeader, row.case_name, row.config, m.frames,
                   partner_cell(row.aligned, m.mean_joint_error_cm, 1),
                   partner_cell(hands, m.median_hand_error_cm, 2),
                   partner_cell(hands, m.mean_hand_error_cm, 2), m.hand_samples,
                   percent(m.slip_rate), fmt::format("{:.1f}", m.ground_speed_cm_s),
                   partner_cell(m.jumps > 0, m.max_jump_speed_deg_s, 0),
                   partner_cell(m.jumps > 0, m.median_jump_speed_deg_s, 0),
                   partner_cell(row.aligned && m.jumps > 0, m.median_true_jump_speed_deg_s, 0),
                   m.jumps ? fmt::format("{}/{}", m.jumps_over_reference, m.jumps) : "-",
                   row.aligned && m.jumps ? fmt::format("{}/{}", m.jumps_over_truth, m.jumps) : "-",
                   m.jumps ? fmt::format("{}/{}", m.jumps_over_window_reference, m.jumps) : "-",
                   row.aligned && m.jumps
                       ? fmt::format("{}/{}", m.jumps_over_window_reference_and_truth, m.jumps)
                       : "-",
                   fmt::format("{:.0f}", m.mean_jerk_mps3),
                   fmt::format("{:.0f}", m.true_mean_jerk_mps3),
                   fmt::format("{:.1f}", m.mean_step_us));
  }
  case_footer(report.partner_rows.back());
  append_partner_legend(out, report.partner_options);
  append_steadiness_table(out, report);
}

void append_partner_csv_row(std::string& out, const PartnerRow& row, const std::string& take,
                            const std::string& take_name, const PartnerMetrics& m) {
  fmt::format_to(std::back_inserter(out),
                 "{},{},{},{},{},{},{:.4f},{},{:.4f},{:.4f},{:.5f},{:.5f},{:.3f},{:.3f},{},{:.2f},"
                 "{:.2f},{},"
                 "{:.2f},{},{:.2f},{:.5f},{:.3f},{:.2f},{:.2f},{},{},{:.2f},{:.2f},{:.2f},{:.2f},"
                 "{:.3f},{:.3f},{},{:.2f},{:.2f},{:.3f},{},{:.3f},{},{:.4f},{:.2f},{},{},{:.1f}\n",
                 row.case_name, row.config, take, take_name, row.aligned ? 1 : 0, m.frames,
                 m.mean_joint_error_cm, m.hand_samples, m.median_hand_error_cm,
                 m.mean_hand_error_cm, m.slip_rate, m.captured_slip_rate, m.ground_speed_cm_s,
                 m.captured_ground_speed_cm_s, m.jumps, m.max_jump_speed_deg_s,
                 m.median_jump_speed_deg_s, m.jumps_over_reference, m.median_true_jump_speed_deg_s,
                 m.jumps_over_truth, m.reference_speed_deg_s, m.captured_windows_over_reference,
                 m.mean_step_us, row.loop_step_us, m.window_reference_speed_deg_s,
                 m.jumps_over_window_reference, m.jumps_over_window_reference_and_truth,
                 m.mean_jerk_mps3, m.true_mean_jerk_mps3, m.frame_speed_deg_s,
                 m.captured_frame_speed_deg_s, m.median_rejoin_s, m.max_rejoin_s,
                 m.jumps_rejoined_in_time, m.median_spacing_error_cm, m.max_spacing_error_cm,
                 m.max_jump_slide_mps, m.jumps_sliding, m.max_slide_mps, m.sliding_frames,
                 m.median_sensed_hand_error_cm, m.true_frame_speed_deg_s, m.jumps_crowded,
                 m.crowded_frames, m.closest_cm);
}

// reliability.dat and its plot: per case, the 10 confidence bins of the first tracker (hmm when
// it ran) as (mean confidence, accuracy), one gnuplot data block per case; empty bins left out.
void append_reliability_plot(const EvalReport& report, const std::vector<std::string>& trackers,
                             const std::string& terminal, std::vector<PlotFile>& files,
                             std::string& script) {
  if (trackers.empty()) return;
  const std::string tracker =
      std::ranges::find(trackers, "hmm") != trackers.end() ? "hmm" : trackers.front();
  std::string data = "# per case (one block each): bin mean_confidence accuracy frames\n";
  std::vector<std::string> titles;
  for (const EvalRow& row : report.rows) {
    if (row.tracker != tracker) continue;
    fmt::format_to(std::back_inserter(data), "# {} (ECE {:.2f}%)\n", row.case_name,
                   100.0 * row.metrics.confidence_ece);
    for (std::size_t b = 0; b < row.metrics.reliability.size(); ++b) {
      const ReliabilityBin& bin = row.metrics.reliability[b];
      if (bin.frames == 0) continue;
      fmt::format_to(std::back_inserter(data), "{} {:.5f} {:.5f} {}\n", b, bin.mean_confidence,
                     bin.accuracy, bin.frames);
    }
    data += "\n\n";
    titles.push_back(
        fmt::format("{} (ECE {:.1f}%)", row.case_name, 100.0 * row.metrics.confidence_ece));
  }
  files.push_back({"reliability.dat", data});
  script += fmt::format(
      "\nreset\n"
      "set terminal {} size 1000,800 font ',11' noenhanced\n"
      "set output 'reliability.png'\n"
      "set title 'Reliability of the {} confidence: share within 100 ms per confidence bin'\n"
      "set xlabel 'mean confidence in bin'\n"
      "set ylabel 'frames within 100 ms'\n"
      "set xrange [0:1]\n"
      "set yrange [0:1]\n"
      "set size square\n"
      "set key outside right top\n"
      "set grid\n"
      "plot x with lines dt 2 lc rgb 'black' title 'calibrated'",
      terminal, tracker);
  for (std::size_t k = 0; k < titles.size(); ++k) {
    script += fmt::format(
        ", \\\n     'reliability.dat' index {} using 2:3 with linespoints pt 7 ps 0.8 title '{}'",
        k, titles[k]);
  }
  script += "\n";
}

}  // namespace

std::string format_partner_csv(const EvalReport& report) {
  std::string out =
      "case,corrections,take,take_name,aligned,frames,mean_joint_error_cm,hand_samples,"
      "median_hand_error_cm,mean_hand_error_cm,slip_rate,captured_slip_rate,skate_speed_cm_s,"
      "captured_skate_speed_cm_s,jumps,"
      "max_jump_speed_deg_s,median_jump_speed_deg_s,jumps_over_reference,median_true_jump_speed_"
      "deg_s,"
      "jumps_over_truth,reference_speed_deg_s,"
      "captured_windows_over_reference,mean_step_us,loop_step_us,window_reference_speed_deg_s,"
      "jumps_over_window_reference,jumps_over_window_reference_and_truth,mean_jerk_mps3,"
      "true_mean_jerk_mps3,frame_speed_deg_s,captured_frame_speed_deg_s,median_rejoin_s,"
      "max_rejoin_s,jumps_rejoined_in_time,median_spacing_error_cm,max_spacing_error_cm,"
      "max_jump_slide_mps,jumps_sliding,max_slide_mps,sliding_frames,median_sensed_hand_error_cm,"
      "true_frame_speed_deg_s,jumps_crowded,crowded_frames,closest_cm\n";
  for (const PartnerRow& row : report.partner_rows) {
    for (const auto& [take, metrics] : row.per_take) {
      append_partner_csv_row(out, row, std::to_string(take), take_name(report, take), metrics);
    }
    append_partner_csv_row(out, row, "all", "", row.metrics);
  }
  return out;
}

std::string format_eval_table(const EvalReport& report) {
  std::string out;
  constexpr const char* kHeader =
      "{:<18} {:<14} {:>7} {:>7} {:>7} {:>7} {:>6} {:>7} {:>8} {:>7} {:>7} {:>7} {:>6} {:>6} "
      "{:>8} {:>6} {:>8}\n";
  fmt::format_to(std::back_inserter(out), kHeader, "case", "tracker", "frames", "acc@50", "acc@100",
                 "alike", "find s", "acc@300", "mean ms", "med ms", "jumps", "recov s", "fj/min",
                 "lost", "lost trk", "ECE", "us/frame");
  std::string previous_case;
  for (const EvalRow& row : report.rows) {
    if (!previous_case.empty() && row.case_name != previous_case) out += "\n";
    previous_case = row.case_name;
    const Metrics& m = row.metrics;
    const std::string jumps =
        m.jumps ? fmt::format("{}/{}", m.recovered_jumps, m.jumps) : std::string("-");
    fmt::format_to(std::back_inserter(out), kHeader, row.case_name, row.tracker, m.scored_frames,
                   percent(m.within_50ms), percent(m.within_100ms), percent(m.within_100ms_alike),
                   find_text(m), percent(m.within_300ms), fmt::format("{:.1f}", m.mean_error_ms),
                   fmt::format("{:.1f}", m.median_error_ms), jumps, recovery_text(m),
                   fmt::format("{:.1f}", m.false_jumps_per_minute), percent(m.lost_fraction),
                   percent(m.lost_on_tracked_fraction), percent(m.confidence_ece),
                   fmt::format("{:.0f}", m.mean_step_us));
  }
  const NaiveCheck& n = report.naive;
  if (n.ran) {
    fmt::format_to(
        std::back_inserter(out),
        "\nnaive O(M^2) forward vs O(M) hmm, same parameters, on take {} alone ({} states), case "
        "{}:\n  same state on {}/{} frames ({}); acc@100 naive {} vs hmm {}; {:.0f} vs {:.0f} "
        "us/frame (tracker step only)\n",
        n.take_name, n.states, n.case_name, n.same_state, n.frames,
        percent(n.frames ? static_cast<double>(n.same_state) / static_cast<double>(n.frames) : 0.0),
        percent(n.naive.within_100ms), percent(n.fast.within_100ms), n.naive.mean_step_us,
        n.fast.mean_step_us);
  }
  append_partner_table(out, report);
  return out;
}

std::string format_eval_csv(const EvalReport& report) {
  std::string out =
      "case,tracker,take,take_name,frames,scored_frames,pause_frames,acc_50ms,acc_100ms,acc_300ms,"
      "miss_fraction,mean_error_ms,median_error_ms,jumps,recovered_jumps,median_recovery_s,"
      "mean_recovery_s,lost_fraction,mean_step_us,reported_jumps,false_jumps,"
      "false_jumps_per_minute,lost_on_tracked_fraction,confidence_ece,lost_switches_per_minute,"
      "acc_100ms_alike,median_find_s,worst_find_s,acc_100ms_found\n";
  for (const EvalRow& row : report.rows) {
    for (const auto& [take, metrics] : row.per_take) {
      append_csv_row(out, row.case_name, row.tracker, std::to_string(take), take_name(report, take),
                     metrics);
    }
    append_csv_row(out, row.case_name, row.tracker, "all", "", row.metrics);
  }
  const NaiveCheck& n = report.naive;
  if (n.ran) {
    append_csv_row(out, n.case_name, "naive-hmm", std::to_string(n.take), n.take_name, n.naive);
    append_csv_row(out, n.case_name, "hmm-one-take", std::to_string(n.take), n.take_name, n.fast);
  }
  return out;
}

std::string format_frames_csv(const EvalReport& report) {
  std::string out =
      "case,tracker,take,error_ms,confidence,window_mass,best_distance_per_dim,"
      "sensor_noise_per_dim,lost,in_pause,jumped,true_take,true_frame,estimated_take,"
      "estimated_frame,true_jump,outlier,tracker_confidence,rig_offset,rig_offset_learnt_s,"
      "frame_offset\n";
  for (const EvalRow& row : report.rows) {
    for (const ScoredFrame& f : row.frames) {
      const FrameEstimate& e = f.estimate;
      fmt::format_to(std::back_inserter(out),
                     "{},{},{},{:.1f},{:.5f},{:.5f},{:.6f},{:.7f},{},{},{},{},{:.1f},{},{},{},{},"
                     "{:.5f},{:.5f},{:.3f},{:.3f}\n",
                     row.case_name, row.tracker, f.take, f.error_ms, e.confidence, e.window_mass,
                     e.best_distance_per_dim, e.sensor_noise_per_dim, e.lost ? 1 : 0,
                     e.in_pause ? 1 : 0, e.jumped ? 1 : 0, f.truth.take, f.truth.template_frame,
                     e.take, e.frame_in_take, f.truth.jump ? 1 : 0, e.outlier ? 1 : 0,
                     e.tracker_confidence, e.rig_offset, e.rig_offset_learnt_s, e.frame_offset);
    }
  }
  return out;
}

std::vector<PlotFile> make_eval_plots(const EvalReport& report, const std::string& terminal) {
  std::vector<PlotFile> files;
  std::vector<std::string> cases, trackers;
  for (const EvalRow& row : report.rows) {
    if (std::ranges::find(cases, row.case_name) == cases.end()) cases.push_back(row.case_name);
    if (std::ranges::find(trackers, row.tracker) == trackers.end()) trackers.push_back(row.tracker);
  }

  // accuracy.dat: one line per case, one column per tracker (percent within 100 ms).
  std::string accuracy = "# case";
  for (const std::string& t : trackers) accuracy += " " + t;
  accuracy += "\n";
  for (const std::string& c : cases) {
    accuracy += c;
    for (const std::string& t : trackers) {
      const auto it = std::ranges::find_if(
          report.rows, [&](const EvalRow& r) { return r.case_name == c && r.tracker == t; });
      accuracy += it == report.rows.end()
                      ? " NaN"
                      : fmt::format(" {:.2f}", 100.0 * it->metrics.within_100ms);
    }
    accuracy += "\n";
  }
  files.push_back({"accuracy.dat", accuracy});

  std::string script = fmt::format(
      "# duet eval plots: run `gnuplot plots.gp` in this directory.\n"
      "set terminal {} size 1400,650 font ',11' noenhanced\n"
      "set output 'accuracy.png'\n"
      "set title 'Frames within 100 ms of the true template time (pause frames excluded)'\n"
      "set style data histograms\n"
      "set style histogram clustered gap 1\n"
      "set style fill solid 0.85 border -1\n"
      "set boxwidth 0.9\n"
      "set yrange [0:105]\n"
      "set ylabel 'within 100 ms (%)'\n"
      "set grid ytics\n"
      "set xtics rotate by -30 left\n"
      "set key outside right top\n"
      "set bmargin 6\n",
      terminal);
  script += "plot ";
  for (std::size_t k = 0; k < trackers.size(); ++k) {
    script += fmt::format("{}'accuracy.dat' using {}{} title '{}'", k ? ", \\\n     " : "", k + 2,
                          k == 0 ? ":xtic(1)" : "", trackers[k]);
  }
  script += "\n";

  if (!report.traces.empty()) {
    // trace.dat: time, true frame (NaN in a pause), true frame in a pause, then per tracker the
    // estimated frame in the performed take (NaN elsewhere) and a marker row for other takes.
    const EvalTrace& first = report.traces.front();
    const double other_take_y = -150.0;
    std::string data = "# time_s truth truth_in_pause";
    for (const EvalTrace& t : report.traces) data += " " + t.tracker + " " + t.tracker + "_other";
    data += "\n";
    for (std::size_t f = 0; f < first.times_s.size(); ++f) {
      const TruthFrame& truth = first.truth[f];
      fmt::format_to(std::back_inserter(data), "{:.4f} {} {}", first.times_s[f],
                     truth.in_pause ? "NaN" : fmt::format("{:.2f}", truth.template_frame),
                     truth.in_pause ? fmt::format("{:.2f}", truth.template_frame) : "NaN");
      for (const EvalTrace& t : report.traces) {
        const FrameEstimate& e = t.estimates[f];
        const bool same = e.take == truth.take && e.take >= 0;
        fmt::format_to(std::back_inserter(data), " {} {}",
                       same ? std::to_string(e.frame_in_take) : "NaN",
                       same ? "NaN" : fmt::format("{:.0f}", other_take_y));
      }
      data += "\n";
    }
    files.push_back({"trace.dat", data});

    script += fmt::format(
        "\nreset\n"
        "set terminal {} size 1600,700 font ',11' noenhanced\n"
        "set output 'trace.png'\n"
        "set title 'case {} on take {}: true vs estimated template frame (points at {:.0f}: "
        "estimate in another take)'\n"
        "set xlabel 'performance time (s)'\n"
        "set ylabel 'template frame in take'\n"
        "set key outside right top\n"
        "set grid\n"
        "plot ",
        terminal, first.case_name, take_name(report, first.take), other_take_y);
    // The truth first, so it lies underneath: the trackers' points drawn after it stay visible
    // where they agree with it (drawn the other way round, the truth line hid a right estimate).
    script +=
        "'trace.dat' using 1:($2) with lines lw 1.5 lc rgb 'black' title 'truth', \\\n"
        "     'trace.dat' using 1:($3) with lines lw 4 lc rgb 'red' title 'truth (pause)'";
    for (std::size_t k = 0; k < report.traces.size(); ++k) {
      const int column = 4 + 2 * static_cast<int>(k);
      script += fmt::format(
          ", \\\n     'trace.dat' using 1:(${}) with points pt 7 ps 0.5 lc {} title '{}', \\\n"
          "     'trace.dat' using 1:(${}) with points pt 2 ps 0.6 lc {} notitle",
          column, k + 1, report.traces[k].tracker, column + 1, k + 1);
    }
    script += "\n";
  }
  append_reliability_plot(report, trackers, terminal, files, script);
  files.push_back({"plots.gp", script});
  return files;
}

}  // namespace duet
