// Private helpers for the readers in src/io: read a whole file at once; tokens in messages.
// (Writing goes through duet/io/atomic_write.h.)
#pragma once

#include <string>
#include <string_view>

#include "duet/base/result.h"

namespace duet::io_internal {

// ASCII-only, locale-independent helpers shared by the readers' tokenizers.
inline char ascii_lower(char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c + 32) : c; }
bool equals_ignore_case(std::string_view a, std::string_view b);

// A token quoted for an error message: at most 40 bytes, non-printable bytes as \xNN.
std::string quoted_token(std::string_view token);

// Reads the whole file into memory in one call (no per-line or per-number stream I/O).
// Errors name the path: "walk.bvh: cannot open: No such file or directory".
Result<std::string> read_text_file(const std::string& path);

}  // namespace duet::io_internal
