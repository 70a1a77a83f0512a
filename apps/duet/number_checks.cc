#include "number_checks.h"

#include <fmt/format.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <functional>

namespace duet::app {

namespace {

// A finite number (no nan, no inf, no overflow) for which `accept` holds; else "must be ...".
CLI::Validator finite_number(std::function<bool(double)> accept, const std::string& must_be,
                             const std::string& description) {
  return CLI::Validator(
      [accept = std::move(accept), must_be](std::string& text) -> std::string {
        errno = 0;
        char* end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        const bool parsed = !text.empty() && end == text.c_str() + text.size() && errno != ERANGE;
        if (parsed && std::isfinite(value) && accept(value)) return {};
        return fmt::format("must be {}, got '{}'", must_be, text);
      },
      description);
}

}  // namespace

CLI::Validator number_between(double low, double high, const std::string& unit) {
  const std::string suffix = unit.empty() ? "" : " " + unit;
  return finite_number([low, high](double v) { return v >= low && v <= high; },
                       fmt::format("between {:g} and {:g}{}", low, high, suffix),
                       fmt::format("{:g}..{:g}{}", low, high, suffix));
}

CLI::Validator positive_check() {
  return finite_number([](double v) { return v > 0.0; }, "a finite number > 0", "POSITIVE");
}

CLI::Validator non_negative_check() {
  return finite_number([](double v) { return v >= 0.0; }, "a finite number >= 0", "NONNEGATIVE");
}

CLI::Validator cap_check() {
  const CLI::Validator finite = non_negative_check();
  return CLI::Validator(
      [finite](std::string& text) -> std::string {
        if (text == "inf") return {};
        return finite(text).empty()
                   ? std::string()
                   : fmt::format("must be a finite number >= 0 or inf, got '{}'", text);
      },
      "NONNEGATIVE|inf");
}

CLI::Validator fps_check() { return number_between(kMinFps, kMaxFps, "fps"); }

CLI::Validator scale_check() {
  return number_between(kMinScale, kMaxScale, "metres per file unit");
}

}  // namespace duet::app
