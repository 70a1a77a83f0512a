// The ranges duet accepts for the numbers that size and scale motion, whether they come from the
// command line or from a file: outside them a number is a mistake (a frame rate of 1e9, a scale
// of 1e-300), and accepting it would mean allocating without bound or an unusable result.
#pragma once

namespace duet {

// Frames per second of a clip, a sensor or an output.
inline constexpr double kMinFrameRate = 1.0;
inline constexpr double kMaxFrameRate = 1000.0;

// Metres per file unit: from 0.1 mm (a file in tenths of millimetres) to 1 km.
inline constexpr double kMinMetresPerUnit = 1e-4;
inline constexpr double kMaxMetresPerUnit = 1e3;

// Frames of any clip duet reads or makes: 46 hours at 60 Hz, 2.8 hours at 1000 Hz.
inline constexpr long long kMaxClipFrames = 10'000'000;

}  // namespace duet
