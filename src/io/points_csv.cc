#include "duet/io/points_csv.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "duet/base/parse_number.h"
#include "duet/motion/head_hands.h"
#include "duet/motion/limits.h"
#include "text_file.h"

namespace duet {

namespace {

constexpr int kColumns = 22;
constexpr int kPoints = 3;
constexpr std::array<const char*, kPoints> kPointNames = {"head", "left", "right"};

struct Sample {
  double time_s = 0.0;
  std::array<Vec3, kPoints> positions;
  std::array<Quat, kPoints> rotations;
};

std::string_view trim(std::string_view text) {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t' || text.back() == '\r')) {
    text.remove_suffix(1);
  }
  return text;
}

bool parse_double(std::string_view token, double& value) {
  const std::optional<double> parsed = parse_number<double>(trim(token), PlusSign::kAllowed);
  if (parsed) value = *parsed;
  return parsed.has_value();
}

// The column names of the header, for messages.
const std::array<std::string, kColumns>& column_names() {
  static const std::array<std::string, kColumns> names = [] {
    std::array<std::string, kColumns> n;
    n[0] = "time_s";
    int c = 1;
    for (const char* point : kPointNames) {
      for (const char* field : {"x", "y", "z", "qx", "qy", "qz", "qw"}) {
        n[static_cast<std::size_t>(c++)] = std::string(point) + "_" + field;
      }
    }
    return n;
  }();
  return names;
}

Result<Sample> parse_line(std::string_view line, const std::string& name, int line_number) {
  std::array<double, kColumns> values{};
  int column = 0;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    const std::string_view token =
        line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start);
    if (column >= kColumns) {
      return make_error(name, line_number,
                        fmt::format("more than {} columns (the header's)", kColumns));
    }
    if (!parse_double(token, values[static_cast<std::size_t>(column)])) {
      return make_error(name, line_number,
                        fmt::format("column {} ({}): {} is not a finite number", column + 1,
                                    column_names()[static_cast<std::size_t>(column)],
                                    io_internal::quoted_token(trim(token))));
    }
    ++column;
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  if (column != kColumns) {
    return make_error(name, line_number,
                      fmt::format("{} columns, expected {} (the header's)", column, kColumns));
  }
  Sample sample;
  sample.time_s = values[0];
  for (int p = 0; p < kPoints; ++p) {
    const double* v = &values[static_cast<std::size_t>(1 + 7 * p)];
    sample.positions[static_cast<std::size_t>(p)] = Vec3(v[0], v[1], v[2]);
    Quat q(v[6], v[3], v[4], v[5]);  // w, x, y, z
    const double norm = q.norm();
    // A quaternion far from unit length is not an orientation (a column mix-up, say).
    if (!(norm > 0.5 && norm < 1.5)) {
      return make_error(name, line_number,
                          fmt::format("the {} orientation has length {:.3g}, not a unit "
                                    "quaternion",
                                    kPointNames[static_cast<std::size_t>(p)], norm));
    }
    sample.rotations[static_cast<std::size_t>(p)] = q.normalized();
  }
  return sample;
}

double median_interval(const std::vector<Sample>& samples) {
  std::vector<double> intervals;
  intervals.reserve(samples.size());
  for (std::size_t i = 1; i < samples.size(); ++i) {
    intervals.push_back(samples[i].time_s - samples[i - 1].time_s);
  }
  std::nth_element(intervals.begin(), intervals.begin() + static_cast<long>(intervals.size() / 2),
                   intervals.end());
  return intervals[intervals.size() / 2];
}

}  // namespace

bool is_points_csv_path(const std::string& path) {
  if (path.size() < 4) return false;
  std::string extension = path.substr(path.size() - 4);
  for (char& c : extension) c = io_internal::ascii_lower(c);
  return extension == ".csv";
}

const std::string& points_csv_header() {
  static const std::string header = [] {
    std::string h;
    for (const std::string& column : column_names()) {
      if (!h.empty()) h += ',';
      h += column;
    }
    return h;
  }();
  return header;
}

Result<Clip> parse_points_csv(std::string_view text, const std::string& name,
                              const PointsCsvReadOptions& options) {
  std::vector<Sample> samples;
  bool header_seen = false;
  int line_number = 0;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view line = trim(text.substr(start, end - start));
    start = end + 1;
    ++line_number;
    if (line.empty() || line.front() == '#') continue;
    if (!header_seen) {
      if (line != points_csv_header()) {
        return make_error(name, line_number,
                          "not a three-point CSV: the first line must be the header " +
                              points_csv_header() + " (docs/file-formats.md)");
      }
      header_seen = true;
      continue;
    }
    if (static_cast<long long>(samples.size()) >= options.max_frames) {
      return make_error(name, line_number,
                        fmt::format("more than {} samples", options.max_frames));
    }
    Result<Sample> sample = parse_line(line, name, line_number);
    if (!sample) return sample.error();
    if (!samples.empty() && !(sample.value().time_s > samples.back().time_s)) {
      return make_error(name, line_number,
                        fmt::format("time_s {} does not increase (previous {})",
                                    sample.value().time_s, samples.back().time_s));
    }
    samples.push_back(std::move(sample).value());
  }
  if (!header_seen) return make_error(name, 0, "empty file: no header line");
  if (samples.size() < 2) return make_error(name, 0, "fewer than two samples");

  double rate = options.frame_rate.value_or(std::round(1.0 / median_interval(samples)));
  if (!(rate >= kMinFrameRate && rate <= kMaxFrameRate)) {
    return make_error(name, 0,
                      fmt::format("sample rate {:.4g} Hz is outside {}-{} Hz (are the times in "
                                  "seconds?)",
                                  rate, kMinFrameRate, kMaxFrameRate));
  }
  const double duration = samples.back().time_s - samples.front().time_s;
  const double frames_exact = std::floor(duration * rate + 1e-6) + 1.0;
  if (frames_exact > static_cast<double>(std::min(options.max_frames, kMaxClipFrames))) {
    return make_error(name, 0, fmt::format("{:.0f} s at {} Hz is more than {} frames", duration,
                                           rate, std::min(options.max_frames, kMaxClipFrames)));
  }
  if (frames_exact < 2.0) {
    return make_error(name, 0,
                      fmt::format("the samples span {:.6g} s, less than two frames at {} Hz",
                                  duration, rate));
  }
  const int frames = static_cast<int>(frames_exact);
  Clip clip(make_head_hands_skeleton(), rate, frames);
  std::size_t next = 1;  // samples[next - 1] <= t < samples[next]
  for (int f = 0; f < frames; ++f) {
    const double t = samples.front().time_s + f / rate;
    while (next + 1 < samples.size() && samples[next].time_s <= t) ++next;
    const Sample& a = samples[next - 1];
    const Sample& b = samples[next];
    const double w = std::clamp((t - a.time_s) / (b.time_s - a.time_s), 0.0, 1.0);
    for (int p = 0; p < kPoints; ++p) {
      const auto i = static_cast<std::size_t>(p);
      clip.translations_ls(f)[i + 1] = (1.0 - w) * a.positions[i] + w * b.positions[i];
      clip.rotations_ls(f)[i + 1] = a.rotations[i].slerp(w, b.rotations[i]).normalized();
    }
  }
  return clip;
}

Result<Clip> read_points_csv(const std::string& path, const PointsCsvReadOptions& options) {
  Result<std::string> text = io_internal::read_text_file(path);
  if (!text) return text.error();
  return parse_points_csv(text.value(), path, options);
}

std::string format_points_csv(const Clip& points) {
  std::string out = points_csv_header() + "\n";
  for (int f = 0; f < points.frame_count(); ++f) {
    out += fmt::format("{:.9f}", f / points.frame_rate());
    // The points are children of the origin joint, which a turned world (turn_world) turns.
    const Quat& origin_rotation = points.rotations_ls(f)[kPointsOrigin];
    const Vec3& origin = points.translations_ls(f)[kPointsOrigin];
    for (int p = 1; p <= kPoints; ++p) {
      const Vec3 x =
          origin + origin_rotation * points.translations_ls(f)[static_cast<std::size_t>(p)];
      const Quat q = origin_rotation * points.rotations_ls(f)[static_cast<std::size_t>(p)];
      out += fmt::format(",{:.5f},{:.5f},{:.5f},{:.6f},{:.6f},{:.6f},{:.6f}", x.x(), x.y(), x.z(),
                         q.x(), q.y(), q.z(), q.w());
    }
    out += '\n';
  }
  return out;
}

}  // namespace duet
