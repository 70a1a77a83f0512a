// Turning an EvalReport into text: the table printed by `duet eval`, a CSV file, and gnuplot
// scripts with their data (the command runs gnuplot; this code only writes text).
#pragma once

#include <string>
#include <vector>

#include "duet/eval/runner.h"

namespace duet {

// One line per case x tracker (pooled over the performed takes), then the naive check, then the
// partner metrics when they ran.
std::string format_eval_table(const EvalReport& report);

// Header plus one row per case x tracker x take and one pooled row (take "all") per case x
// tracker; the naive check adds rows for "naive-hmm" and "hmm-one-take". Columns are listed in
// docs/evaluation.md.
std::string format_eval_csv(const EvalReport& report);

// The partner metrics (EvalReport::partner_rows): header plus one row per case x configuration x
// take and one pooled row (take "all") per case x configuration. Columns in docs/evaluation.md.
std::string format_partner_csv(const EvalReport& report);

// Every kept frame (EvalOptions::keep_frames): case, tracker, take, error, and what the tracker
// said (confidence, window mass, best distance, sensor noise, lost, pause). Columns in
// docs/evaluation.md.
std::string format_frames_csv(const EvalReport& report);

struct PlotFile {
  std::string name;  // file name inside the plot directory
  std::string content;
};

// Data files and one gnuplot script ("plots.gp", to be run inside the plot directory) that draws
//   accuracy.png  frames within 100 ms per case and tracker (bar chart);
//   trace.png     estimated vs true template frame over time for report.traces (if any).
// terminal: a gnuplot PNG terminal, "pngcairo" or "png".
std::vector<PlotFile> make_eval_plots(const EvalReport& report, const std::string& terminal);

}  // namespace duet
