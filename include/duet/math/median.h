// The middle of a set of values, for robust summaries (a floor's height, a calibration pose).
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace duet {

// The value in the middle of `values` once sorted (of the two middle ones, the upper); 0 for none.
// Reorders its own copy (std::nth_element, O(n)): pass an rvalue to spare the copy.
inline double upper_median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace duet
