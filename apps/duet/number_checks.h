// The one place that says which numbers the command line accepts: frame rates, scales, durations
// and factors, each within a range a real capture can have. CLI11's PositiveNumber lets through
// nan, 1e-300 and 1e300 (and prints a 309-digit bound for 0); these checks reject them with the
// range in words and exit 2 like any bad command line.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "duet/motion/limits.h"

namespace duet::app {

// Frame rates (Hz) of files, sensors and outputs; metres per file unit (duet/motion/limits.h:
// library files take the same ranges).
inline constexpr double kMinFps = kMinFrameRate;
inline constexpr double kMaxFps = kMaxFrameRate;
inline constexpr double kMinScale = kMinMetresPerUnit;
inline constexpr double kMaxScale = kMaxMetresPerUnit;
// Durations of performances and segments (s): up to a day.
inline constexpr double kMaxDurationS = 86400.0;

// A finite number within [low, high]; the message says "must be between LOW and HIGH UNIT".
CLI::Validator number_between(double low, double high, const std::string& unit = "");
// Finite numbers > 0 and >= 0: CLI::PositiveNumber and CLI::NonNegativeNumber without nan and inf.
CLI::Validator positive_check();
CLI::Validator non_negative_check();
// A cap on a distance: a finite number >= 0, or "inf" for none.
CLI::Validator cap_check();

CLI::Validator fps_check();    // kMinFps..kMaxFps frames per second ("fps")
CLI::Validator scale_check();  // kMinScale..kMaxScale metres per file unit

}  // namespace duet::app
