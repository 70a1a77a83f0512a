// Benchmark support: the 14 salsa duets as BVH pairs (subject 60 leads, 61 follows), the library
// the benchmarks follow against. Take 08 is missing from the BVH copy.
#pragma once

#include <string>
#include <vector>

#include "duet/live/duet_library.h"

namespace duet::bench {

inline const std::string kSalsa = std::string(DUET_DATA_DIR) + "/cmu-salsa";

inline std::vector<PairFiles> salsa_pairs() {
  std::vector<PairFiles> pairs;
  for (const char* t :
       {"01", "02", "03", "04", "05", "06", "07", "09", "10", "11", "12", "13", "14", "15"}) {
    pairs.push_back(PairFiles{{kSalsa + "/bvh/60/60_" + t + "_scaled.bvh"},
                              {kSalsa + "/bvh/61/61_" + t + "_scaled.bvh"}});
  }
  return pairs;
}

}  // namespace duet::bench
