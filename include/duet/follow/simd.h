// Which instruction set the follower's per-frame kernels use (emission distances and the
// exponentials of eq. 7 and 11). Chosen at run time, so one binary runs on any x86-64: AVX2 with
// FMA and F16C (the template's half-precision features) where the CPU has them (every x86-64 with
// AVX2 so far), the portable scalar/Eigen code elsewhere. The environment variable
// DUET_SIMD=scalar forces the portable code (to compare both paths on one machine).
#pragma once

namespace duet {

enum class SimdLevel { kScalar, kAvx2 };

const char* to_string(SimdLevel level) noexcept;

// True when this CPU can run level (kScalar always).
bool cpu_supports(SimdLevel level) noexcept;

// The best level this CPU supports, or kScalar when DUET_SIMD=scalar. Reads the CPU and the
// environment on every call.
SimdLevel detect_simd_level() noexcept;

// The level the kernels use: detect_simd_level() on first use, unless set_simd_level chose one.
SimdLevel simd_level() noexcept;

// Makes the kernels use level from now on (tests and benchmarks compare the paths in one run).
// Returns false and changes nothing when the CPU cannot run it.
bool set_simd_level(SimdLevel level) noexcept;

}  // namespace duet
