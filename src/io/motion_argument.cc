#include "duet/io/motion_argument.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <system_error>

namespace duet {

namespace {

std::string extension_of(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

bool is_regular_file(const std::string& path) {
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec);
}

}  // namespace

Result<std::vector<std::string>> split_motion_argument(const std::string& word) {
  if (word.empty()) return Error{"empty motion file name"};
  std::vector<std::string> parts;
  if (is_regular_file(word)) {
    parts.push_back(word);
  } else {
    std::size_t start = 0;
    while (true) {
      const std::size_t plus = word.find('+', start);
      parts.push_back(word.substr(start, plus == std::string::npos ? plus : plus - start));
      if (plus == std::string::npos) break;
      start = plus + 1;
    }
  }
  if (parts.size() > 2) {
    return Error{"'" + word + "': a motion is one .bvh file or SKELETON.asf+MOTION.amc, not " +
                 std::to_string(parts.size()) + " files"};
  }
  for (const std::string& part : parts) {
    if (part.empty()) return Error{"'" + word + "': empty file name around '+'"};
    if (!is_regular_file(part)) {
      std::error_code ec;
      const std::string problem =
          std::filesystem::exists(part, ec) ? "not a regular file: " : "no such file: ";
      return Error{parts.size() == 1 ? problem + part : "'" + word + "': " + problem + part};
    }
  }
  if (parts.size() == 1) {
    const std::string ext = extension_of(parts[0]);
    if (ext == ".asf") {
      return Error{"'" + word + "' is a skeleton without motion: give SKELETON.asf+MOTION.amc"};
    }
    if (ext == ".amc") {
      return Error{"'" + word + "' is a motion without its skeleton: give SKELETON.asf+MOTION.amc"};
    }
    return parts;
  }
  const std::string a = extension_of(parts[0]), b = extension_of(parts[1]);
  if (!((a == ".asf" && b == ".amc") || (a == ".amc" && b == ".asf"))) {
    return Error{"'" + word + "': two files joined by '+' must be one .asf and one .amc"};
  }
  if (a == ".amc") std::swap(parts[0], parts[1]);
  return parts;
}

std::string join_motion_argument(const std::vector<std::string>& paths) {
  std::string word;
  for (const std::string& p : paths) word += (word.empty() ? "" : "+") + p;
  return word;
}

}  // namespace duet
