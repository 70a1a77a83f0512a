// A progress line on stderr for long work ("loading duets [=====>    ] 5/14"). Quiet when
// stderr is not a terminal, except for the final line.
#pragma once

#include <string>

namespace duet::app {

class ProgressBar {
 public:
  explicit ProgressBar(std::string label);
  void update(long long done, long long total);
  void finish();

 private:
  std::string label_;
  bool terminal_ = false;
  int last_permille_ = -1;
  long long done_ = 0, total_ = 0;
  bool finished_ = false;
};

}  // namespace duet::app
