#include "duet/follow/simd.h"

#include <atomic>
#include <cstdlib>
#include <cstring>

namespace duet {
namespace {

constexpr int kUnset = -1;
// The active level; kUnset until the first kernel call or set_simd_level. Relaxed is enough:
// every value written is a valid choice, and the kernels agree to within rounding.
std::atomic<int> active_level{kUnset};

}  // namespace

const char* to_string(SimdLevel level) noexcept {
  return level == SimdLevel::kAvx2 ? "avx2" : "scalar";
}

bool cpu_supports(SimdLevel level) noexcept {
  if (level == SimdLevel::kScalar) return true;
#if defined(__x86_64__)
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
         __builtin_cpu_supports("f16c");
#else
  return false;
#endif
}

SimdLevel detect_simd_level() noexcept {
  const char* forced = std::getenv("DUET_SIMD");
  if (forced != nullptr && std::strcmp(forced, "scalar") == 0) return SimdLevel::kScalar;
  return cpu_supports(SimdLevel::kAvx2) ? SimdLevel::kAvx2 : SimdLevel::kScalar;
}

SimdLevel simd_level() noexcept {
  int level = active_level.load(std::memory_order_relaxed);
  if (level == kUnset) {
    level = static_cast<int>(detect_simd_level());
    active_level.store(level, std::memory_order_relaxed);
  }
  return static_cast<SimdLevel>(level);
}

bool set_simd_level(SimdLevel level) noexcept {
  if (!cpu_supports(level)) return false;
  active_level.store(static_cast<int>(level), std::memory_order_relaxed);
  return true;
}

}  // namespace duet
