// Numbers read from text as a whole (command-line items, file fields, addresses' ports): one
// place for std::from_chars's rules, so every reader takes and refuses the same spellings.
#pragma once

#include <charconv>
#include <cmath>
#include <optional>
#include <string_view>
#include <system_error>
#include <type_traits>

namespace duet {

// Whether a leading '+' is taken (some files write "+0.5"; from_chars takes none).
enum class PlusSign : bool { kRefused, kAllowed };

// `text` as a number of type T when the whole of it is one: std::from_chars's spellings (no
// whitespace, no "0x"), for a floating-point T a finite value only, a leading '+' only when
// allowed (and never before a '-'); nullopt otherwise, also for a value out of T's range.
template <typename T>
std::optional<T> parse_number(std::string_view text, PlusSign plus = PlusSign::kRefused) noexcept {
  if (plus == PlusSign::kAllowed && !text.empty() && text.front() == '+') {
    text.remove_prefix(1);
    if (!text.empty() && text.front() == '-') return std::nullopt;
  }
  if (text.empty()) return std::nullopt;
  T value{};
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  if constexpr (std::is_floating_point_v<T>) {
    if (!std::isfinite(value)) return std::nullopt;
  }
  return value;
}

}  // namespace duet
