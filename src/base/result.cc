#include "duet/base/result.h"

namespace duet {

Error make_error(const std::string& file, int line, const std::string& reason) {
  if (line > 0) return {file + ":" + std::to_string(line) + ": " + reason};
  return {file + ": " + reason};
}

}  // namespace duet
