#include "io/text_file.h"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <system_error>

namespace duet::io_internal {

namespace {

std::string errno_text(int error) { return std::strerror(error); }

}  // namespace

Result<std::string> read_text_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    return make_error(path, 0, "cannot read: is a directory");
  }
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) return make_error(path, 0, "cannot open: " + errno_text(errno));
  // The size is only a hint (the file may change while we read): read straight into a buffer of
  // that size, then keep reading until end of file.
  std::error_code size_error;
  const auto size = std::filesystem::file_size(path, size_error);
  std::string text;
  std::size_t used = 0;
  text.resize(!size_error && size < (std::uintmax_t{1} << 40) ? static_cast<std::size_t>(size) + 1
                                                              : std::size_t{1} << 16);
  while (true) {
    used += std::fread(text.data() + used, 1, text.size() - used, file);
    if (used < text.size()) break;  // end of file or an error
    text.resize(text.size() * 2);
  }
  text.resize(used);
  const bool failed = std::ferror(file) != 0;
  const int error = errno;
  std::fclose(file);
  if (failed) return make_error(path, 0, "cannot read: " + errno_text(error));
  return text;
}

bool equals_ignore_case(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (ascii_lower(a[i]) != ascii_lower(b[i])) return false;
  }
  return true;
}

std::string quoted_token(std::string_view token) {
  std::string out = "'";
  const std::size_t n = std::min<std::size_t>(token.size(), 40);
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = static_cast<unsigned char>(token[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      static constexpr char kHex[] = "0123456789abcdef";
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
    }
  }
  if (token.size() > n) out += "...";
  out += "'";
  return out;
}

}  // namespace duet::io_internal
