// libFuzzer target for the ASF/AMC reader. The input is "<asf text>\0<amc text>" (no 0 byte: all
// of it is the ASF and the AMC is empty). Seeds: fuzz/corpus/asf_amc/.
//
// Properties checked, beyond "no crash, no hang, no unbounded allocation":
// - an error names the file it is about ("f.asf..." or "f.amc...") and is one line;
// - a clip has a valid skeleton, the root first with 6 channels, every other joint a bone with 3
//   rotation channels (plus 3 position channels for translating bones) or a channel-less End Site;
// - every local rotation is a finite unit quaternion and every translation is finite;
// - the frame count equals the number of frame-number lines of the AMC, counted independently;
// - the same text with CRLF line endings gives the same clip, bit for bit.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "duet/io/asf_amc.h"

namespace {

void check(bool condition, const char* what) {
  if (!condition) {
    std::fprintf(stderr, "asf_amc_fuzz: property violated: %s\n", what);
    std::abort();
  }
}

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

// Lines holding exactly one token made only of digits: the AMC's frame numbers.
long long count_frame_lines(std::string_view amc) {
  long long count = 0;
  std::size_t start = 0;
  while (start < amc.size()) {
    std::size_t end = amc.find('\n', start);
    if (end == std::string_view::npos) end = amc.size();
    std::string_view line = amc.substr(start, end - start);
    while (!line.empty() && is_blank(line.front())) line.remove_prefix(1);
    while (!line.empty() && is_blank(line.back())) line.remove_suffix(1);
    bool digits = !line.empty();
    for (const char c : line) digits = digits && c >= '0' && c <= '9';
    count += digits ? 1 : 0;
    start = end + 1;
  }
  return count;
}

std::string to_crlf(std::string_view text) {
  std::string out;
  out.reserve(text.size() * 2);
  for (const char c : text) {
    if (c == '\n') out += '\r';
    out += c;
  }
  return out;
}

void check_clip(const duet::Clip& clip, std::string_view amc, long long max_frames) {
  const duet::Skeleton& skeleton = clip.skeleton();
  check(skeleton.validate().empty(), "skeleton validates");
  check(clip.frame_count() >= 1 && clip.frame_count() <= max_frames, "frame count in range");
  check(clip.frame_count() == count_frame_lines(amc), "one frame per frame-number line");
  check(skeleton.joints[0].name == "root" && skeleton.joints[0].channels.size() == 6,
        "root first with 6 channels");
  for (int j = 1; j < skeleton.joint_count(); ++j) {
    const duet::Joint& joint = skeleton.joints[static_cast<std::size_t>(j)];
    const std::size_t channels = joint.channels.size();
    check(joint.end_site ? channels == 0 : (channels == 3 || channels == 6), "joint channels");
  }
  for (int f = 0; f < clip.frame_count(); ++f) {
    for (const duet::Quat& q : clip.rotations_ls(f)) {
      check(q.coeffs().allFinite() && std::abs(q.norm() - 1.0) < 1e-9, "unit finite rotation");
    }
    for (const duet::Vec3& t : clip.translations_ls(f)) check(t.allFinite(), "finite translation");
  }
}

bool same_clip(const duet::Clip& a, const duet::Clip& b) {
  if (a.frame_count() != b.frame_count() || a.joint_count() != b.joint_count()) return false;
  for (int f = 0; f < a.frame_count(); ++f) {
    for (int j = 0; j < a.joint_count(); ++j) {
      const auto k = static_cast<std::size_t>(j);
      if (a.translations_ls(f)[k] != b.translations_ls(f)[k]) return false;
      if (a.rotations_ls(f)[k].coeffs() != b.rotations_ls(f)[k].coeffs()) return false;
    }
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const std::size_t split = input.find('\0');
  const std::string_view asf = input.substr(0, split);
  const std::string_view amc =
      split == std::string_view::npos ? std::string_view() : input.substr(split + 1);

  duet::AsfAmcReadOptions options;
  options.max_frames = 100'000;
  const duet::Result<duet::Clip> result = duet::parse_asf_amc(asf, "f.asf", amc, "f.amc", options);
  if (!result) {
    const std::string& message = result.error().message;
    check(message.rfind("f.asf", 0) == 0 || message.rfind("f.amc", 0) == 0, "error names a file");
    check(message.find('\n') == std::string::npos, "error is one line");
    return 0;
  }
  check_clip(result.value(), amc, options.max_frames);

  // CRLF must not change anything (the CMU files are CRLF).
  const std::string asf_crlf = to_crlf(asf), amc_crlf = to_crlf(amc);
  const duet::Result<duet::Clip> again =
      duet::parse_asf_amc(asf_crlf, "f.asf", amc_crlf, "f.amc", options);
  check(again.ok(), "CRLF copy parses");
  check(same_clip(result.value(), again.value()), "CRLF copy gives the same clip");
  return 0;
}
