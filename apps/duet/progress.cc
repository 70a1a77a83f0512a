#include "progress.h"

#include <fmt/format.h>
#include <unistd.h>

namespace duet::app {

ProgressBar::ProgressBar(std::string label)
    : label_(std::move(label)), terminal_(isatty(STDERR_FILENO) != 0) {}

void ProgressBar::update(long long done, long long total) {
  done_ = done;
  total_ = total;
  if (!terminal_ || total <= 0) return;
  const int permille = static_cast<int>(1000 * done / total);
  if (permille == last_permille_) return;
  last_permille_ = permille;
  constexpr int kWidth = 30;
  const int filled = kWidth * permille / 1000;
  fmt::print(stderr, "\r{} [{}{}] {}/{}", label_, std::string(static_cast<std::size_t>(filled), '='),
             std::string(static_cast<std::size_t>(kWidth - filled), ' '), done, total);
  std::fflush(stderr);
}

void ProgressBar::finish() {
  if (finished_) return;
  finished_ = true;
  if (terminal_) fmt::print(stderr, "\r\033[K");
  if (total_ > 0) fmt::print(stderr, "{}: {}/{} done\n", label_, done_, total_);
}

}  // namespace duet::app
