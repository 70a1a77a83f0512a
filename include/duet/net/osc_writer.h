// Writes one OSC bundle (OSC 1.0: "#bundle", a time tag, size-prefixed messages) into a buffer
// sized once, so a frame's bundle is built without allocating (liblo builds every message on the
// heap: lo_message_new, lo_message_add_*, lo_bundle_add_message). Only what Duet sends: messages
// with int32 ('i'), float32 ('f') and string ('s') arguments. Decoded by any OSC library; the
// tests decode it with liblo.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace duet::net {

class OscBundleWriter {
 public:
  explicit OscBundleWriter(std::size_t capacity = 2048);

  // Starts a bundle with the time tag "immediately".
  void begin() noexcept;
  // One message; `types` is the type tags without the comma ("i", "f", "ii", "s"), and the
  // arguments are taken in order from `ints`, `floats` and `strings` by type. Returns false (and
  // the bundle is unusable until begin()) when the buffer is too small or the types are unknown.
  bool message(std::string_view address, std::string_view types,
               std::span<const std::int32_t> ints = {}, std::span<const float> floats = {},
               std::span<const std::string_view> strings = {}) noexcept;
  bool ok() const noexcept { return ok_; }

  std::span<const char> bytes() const noexcept { return {buffer_.data(), size_}; }

 private:
  bool put(const void* data, std::size_t n) noexcept;
  bool put_be32(std::uint32_t value) noexcept;
  bool put_string(std::string_view s) noexcept;  // with its NUL and padding to 4 bytes

  std::vector<char> buffer_;
  std::size_t size_ = 0;
  bool ok_ = false;
};

}  // namespace duet::net
