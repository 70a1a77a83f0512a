// libFuzzer target for the BVH reader and writer. Beyond "no crash, no leak, no hang": whatever
// parses must survive format -> parse with the same skeleton, frame count and frame rate, and
// near-equal translations and rotations. A mismatch aborts with a description.
//
//   cmake -S . -B build-fuzz -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DDUET_BUILD_FUZZERS=ON
//   cmake --build build-fuzz --target bvh_fuzz
//   build-fuzz/fuzz/bvh_fuzz -max_total_time=60 fuzz/corpus/bvh
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "duet/io/bvh.h"

namespace {

[[noreturn]] void fail(const std::string& what, const std::string& text) {
  std::fprintf(stderr, "bvh_fuzz property violated: %s\n--- formatted text ---\n%s\n", what.c_str(),
               text.substr(0, 4000).c_str());
  std::abort();
}

// Largest absolute error the writer may add to a length: fixed notation with 6 decimals rounds
// by at most 5e-7; large values keep their digits, so only relative rounding remains.
bool near_length(double a, double b) {
  return std::abs(a - b) <= 1e-6 + 1e-15 * std::max(std::abs(a), std::abs(b));
}

// Angles written with 6 decimals of a degree differ by at most ~1e-8 rad per angle.
bool near_rotation(const duet::Quat& a, const duet::Quat& b) {
  return std::min((a.coeffs() - b.coeffs()).norm(), (a.coeffs() + b.coeffs()).norm()) < 1e-6;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  duet::BvhReadOptions options;
  options.max_frames = 100'000;  // keeps each run fast; the limit itself is tested elsewhere
  duet::Result<duet::Clip> first = duet::parse_bvh(input, "fuzz.bvh", options);
  if (!first) {
    // Errors must be "file:line: reason" or "file: reason".
    if (first.error().message.rfind("fuzz.bvh:", 0) != 0) {
      fail("error without the source name: " + first.error().message, std::string(input));
    }
    return 0;
  }
  const duet::Clip& a = first.value();
  const std::string text = duet::format_bvh(a);
  duet::Result<duet::Clip> second = duet::parse_bvh(text, "formatted.bvh", options);
  if (!second) fail("formatted text does not parse: " + second.error().message, text);
  const duet::Clip& b = second.value();

  if (a.joint_count() != b.joint_count()) fail("joint count differs", text);
  if (a.frame_count() != b.frame_count()) fail("frame count differs", text);
  if (std::abs(a.frame_rate() - b.frame_rate()) > 1e-12 * a.frame_rate()) {
    fail("frame rate differs", text);
  }
  for (int j = 0; j < a.joint_count(); ++j) {
    const duet::Joint& ja = a.skeleton().joints[static_cast<std::size_t>(j)];
    const duet::Joint& jb = b.skeleton().joints[static_cast<std::size_t>(j)];
    if (ja.name != jb.name || ja.parent != jb.parent || ja.end_site != jb.end_site ||
        ja.channels != jb.channels) {
      fail("joint " + std::to_string(j) + " ('" + ja.name + "') differs", text);
    }
    for (int axis = 0; axis < 3; ++axis) {
      if (!near_length(ja.offset[axis], jb.offset[axis])) {
        fail("offset of joint '" + ja.name + "' differs", text);
      }
    }
  }
  for (int f = 0; f < a.frame_count(); ++f) {
    for (std::size_t j = 0; j < static_cast<std::size_t>(a.joint_count()); ++j) {
      for (int axis = 0; axis < 3; ++axis) {
        if (!near_length(a.translations_ls(f)[j][axis], b.translations_ls(f)[j][axis])) {
          fail("translation differs at frame " + std::to_string(f) + ", joint " + std::to_string(j),
               text);
        }
      }
      if (!near_rotation(a.rotations_ls(f)[j], b.rotations_ls(f)[j])) {
        fail("rotation differs at frame " + std::to_string(f) + ", joint " + std::to_string(j),
             text);
      }
    }
  }
  return 0;
}
