#include "duet/eval/report.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <sstream>

namespace duet {
namespace {

const PlotFile* find_file(const std::vector<PlotFile>& files, const std::string& name) {
  const auto it = std::ranges::find_if(files, [&](const PlotFile& f) { return f.name == name; });
  return it == files.end() ? nullptr : &*it;
}

// A report with one case, two trackers and a 3-frame trace of each.
EvalReport small_report() {
  EvalReport report;
  report.take_names = {"60_01"};
  for (const char* tracker : {"hmm", "nearest"}) {
    EvalRow row;
    row.case_name = "clean";
    row.tracker = tracker;
    report.rows.push_back(row);
    EvalTrace trace;
    trace.case_name = "clean";
    trace.tracker = tracker;
    trace.take = 0;
    trace.template_rate_hz = 60.0;
    for (int f = 0; f < 3; ++f) {
      trace.times_s.push_back(f / 60.0);
      trace.truth.push_back({0, static_cast<double>(f), false, false});
      trace.estimates.push_back({0, f, false, false, 1.0});
    }
    report.traces.push_back(trace);
  }
  return report;
}

// The trace plot's data sources in the order gnuplot draws them (later ones on top).
std::vector<std::string> trace_plot_order(const std::string& script) {
  const std::size_t trace = script.find("set output 'trace.png'");
  EXPECT_NE(trace, std::string::npos) << script;
  const std::size_t plot = script.find("\nplot ", trace);
  EXPECT_NE(plot, std::string::npos) << script;
  std::vector<std::string> order;
  std::istringstream lines(script.substr(plot + 1));
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("set ", 0) == 0 || line == "reset") break;  // the next plot's settings
    const std::size_t title = line.find(" title '");
    if (title == std::string::npos) continue;  // notitle: a tracker's other-take markers
    const std::size_t start = title + 8;
    order.push_back(line.substr(start, line.find('\'', start) - start));
    if (line.back() != '\\') break;  // the plot command ends here
  }
  return order;
}

TEST(EvalReportPlots, TruthIsDrawnFirstAndTheTrackersOnTop) {
  const std::vector<PlotFile> files = make_eval_plots(small_report(), "png");
  const PlotFile* script = find_file(files, "plots.gp");
  ASSERT_NE(script, nullptr);
  ASSERT_NE(find_file(files, "trace.dat"), nullptr);
  const std::vector<std::string> order = trace_plot_order(script->content);
  EXPECT_EQ(order, (std::vector<std::string>{"truth", "truth (pause)", "hmm", "nearest"}))
      << script->content;
  // Each tracker's other-take markers come right after its own points, still above the truth.
  const std::size_t truth = script->content.find("using 1:($2) with lines");
  const std::size_t other = script->content.find("using 1:($5) with points");
  ASSERT_NE(truth, std::string::npos);
  ASSERT_NE(other, std::string::npos);
  EXPECT_LT(truth, other);
}

EvalReport report_with_partner_rows() {
  EvalReport report = small_report();
  PartnerRow row;
  row.case_name = "improv-pause";
  row.config = "all";
  row.metrics.frames = 600;
  row.metrics.mean_joint_error_cm = 7.4;
  row.metrics.hand_samples = 40;
  row.metrics.jumps = 3;
  report.partner_rows.push_back(row);
  row.config = "none";
  row.aligned = false;
  report.partner_rows.push_back(row);
  return report;
}

TEST(EvalReportTable, PartnerColumnsHaveUnitsAndALegend) {
  const std::string table = format_eval_table(report_with_partner_rows());
  const std::size_t header = table.find("\ncase ", table.find("partner metrics"));
  ASSERT_NE(header, std::string::npos) << table;
  std::istringstream lines(table.substr(header + 1));
  std::string names, units;
  std::getline(lines, names);
  std::getline(lines, units);
  // The units line sits under the names: each unit ends where its column's name ends.
  const auto column_end = [](const std::string& line, const std::string& cell) {
    const std::size_t at = line.find(cell);
    return at == std::string::npos ? at : at + cell.size();
  };
  for (const auto& [name, unit] :
       std::vector<std::pair<std::string, std::string>>{{"joint", "cm"},
                                                        {"hand med", "cm"},
                                                        {"hand avg", "cm"},
                                                        {"hand n", "samples"},
                                                        {"slip", "%"},
                                                        {"skate", "cm/s"},
                                                        {"jump max", "deg/s"},
                                                        {"true med", "deg/s"},
                                                        {">p99", "jumps"},
                                                        {"true jerk", "m/s^3"},
                                                        {"us/frame", "us"}}) {
    const std::size_t name_end = column_end(names, name);
    ASSERT_NE(name_end, std::string::npos) << name << " missing from\n" << names;
    ASSERT_GE(units.size(), name_end) << units;
    EXPECT_EQ(units.substr(name_end - unit.size(), unit.size()), unit) << "column " << name << ":\n"
                                                                       << names << "\n"
                                                                       << units;
  }
  // A legend line per column, below the rows.
  const std::size_t legend = table.find("columns (");
  ASSERT_NE(legend, std::string::npos) << table;
  EXPECT_GT(legend, table.find(" none ", header)) << table;
  for (const char* entry :
       {"  frames ", "  joint cm ", "  hand med/avg cm ", "  hand n samples ", "  slip % ",
        "  skate cm/s ", "  jump max/med deg/s ", "  true med deg/s ", "  >p99 jumps ",
        "  >true jumps ", "  >win99 jumps ", "  >w99&t jumps ", "  jerk m/s^3 ", "  us/frame ",
        "  - "}) {
    EXPECT_NE(table.find(entry, legend), std::string::npos) << "legend lacks '" << entry << "'\n"
                                                            << table;
  }
  // The thresholds in the legend are the options' own.
  EXPECT_NE(table.find("within 3 cm of the floor moves faster than 0.2 m/s", legend),
            std::string::npos)
      << table;
}

TEST(EvalReportTable, NoPartnerRowsNoLegend) {
  const std::string table = format_eval_table(small_report());
  EXPECT_EQ(table.find("columns ("), std::string::npos) << table;
}

}  // namespace
}  // namespace duet

namespace duet {
namespace {

TEST(EvalReportPlots, ReliabilityDiagramOfTheHmmPerCase) {
  EvalReport report = small_report();
  CalibrationAccumulator calibration;
  for (int k = 0; k < 10; ++k) calibration.add(0.95, k < 8);  // claims 0.95, right 80%
  report.rows[0].metrics.reliability = calibration.diagram();
  report.rows[0].metrics.confidence_ece = calibration.expected_calibration_error();
  const std::vector<PlotFile> files = make_eval_plots(report, "png");
  const PlotFile* data = find_file(files, "reliability.dat");
  const PlotFile* script = find_file(files, "plots.gp");
  ASSERT_NE(data, nullptr);
  ASSERT_NE(script, nullptr);
  // The hmm row's one filled bin (bin 9: mean confidence 0.95, 80% right, 10 frames); the
  // nearest row is not drawn.
  EXPECT_NE(data->content.find("# clean (ECE 15.00%)\n9 0.95000 0.80000 10\n"), std::string::npos)
      << data->content;
  EXPECT_NE(script->content.find("set output 'reliability.png'"), std::string::npos);
  EXPECT_NE(script->content.find("'reliability.dat' index 0 using 2:3"), std::string::npos);
  EXPECT_EQ(script->content.find("'reliability.dat' index 1"), std::string::npos);
}

TEST(EvalReportCsv, HasTheCalibrationErrorAndTheFramesCsvItsRows) {
  EvalReport report = small_report();
  report.rows[0].metrics.confidence_ece = 0.0123;
  report.rows[0].metrics.within_100ms_alike = 0.875;
  report.rows[0].metrics.median_find_s = 1.5;
  report.rows[0].metrics.worst_find_s = std::numeric_limits<double>::infinity();
  report.rows[0].metrics.within_100ms_found = 0.96;
  FrameEstimate e{0, 5, true, true, 0.0};
  e.confidence = 0.5f;
  e.window_mass = 0.75f;
  e.sensor_noise_per_dim = 0.002f;
  e.tracker_confidence = 0.625f;
  e.rig_offset = 0.04f;
  e.rig_offset_learnt_s = 1.25f;
  e.frame_offset = -0.25f;
  TruthFrame truth;
  truth.take = 0;
  truth.template_frame = 7.0;
  truth.jump = true;
  report.rows[0].frames.push_back({0, 33.3, e, truth});
  const std::string csv = format_eval_csv(report);
  EXPECT_NE(csv.find(",confidence_ece,lost_switches_per_minute,acc_100ms_alike,median_find_s,"
                     "worst_find_s,acc_100ms_found\n"),
            std::string::npos);
  EXPECT_NE(csv.find(",0.01230,0.000,0.87500,1.500,inf,0.96000\n"), std::string::npos) << csv;
  const std::string table = format_eval_table(report);
  EXPECT_NE(table.find("find s"), std::string::npos) << table;
  EXPECT_NE(table.find(" 1.50 "), std::string::npos) << table;
  EXPECT_EQ(format_frames_csv(report),
            "case,tracker,take,error_ms,confidence,window_mass,best_distance_per_dim,"
            "sensor_noise_per_dim,lost,in_pause,jumped,true_take,true_frame,estimated_take,"
            "estimated_frame,true_jump,outlier,tracker_confidence,rig_offset,rig_offset_learnt_s,"
            "frame_offset\n"
            "clean,hmm,0,33.3,0.50000,0.75000,0.000000,0.0020000,1,0,1,0,7.0,0,5,1,0,0.62500,"
            "0.04000,1.250,-0.250\n");
}

}  // namespace
}  // namespace duet
