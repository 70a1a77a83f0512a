// Test support: reading liblo's decoded OSC arguments. lo_arg is a union holding a double, but OSC
// aligns arguments to 4 bytes only: read through bytes, not the union (UBSan reports a misaligned
// member access otherwise).
#pragma once

#include <lo/lo.h>

#include <cstdint>
#include <cstring>

namespace duet::test_osc {

inline std::int32_t arg_int(lo_arg* a) {
  std::int32_t v = 0;
  std::memcpy(&v, a, sizeof v);
  return v;
}
inline float arg_float(lo_arg* a) {
  float v = 0.0f;
  std::memcpy(&v, a, sizeof v);
  return v;
}
inline const char* arg_string(lo_arg* a) { return reinterpret_cast<const char*>(a); }

}  // namespace duet::test_osc
