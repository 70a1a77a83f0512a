#include "duet/net/osc_writer.h"

#include <bit>
#include <cstring>

namespace duet::net {

OscBundleWriter::OscBundleWriter(std::size_t capacity) : buffer_(capacity) {}

bool OscBundleWriter::put(const void* data, std::size_t n) noexcept {
  if (!ok_ || n > buffer_.size() - size_) return ok_ = false;
  std::memcpy(buffer_.data() + size_, data, n);
  size_ += n;
  return true;
}

bool OscBundleWriter::put_be32(std::uint32_t value) noexcept {
  const unsigned char bytes[4] = {
      static_cast<unsigned char>(value >> 24), static_cast<unsigned char>(value >> 16),
      static_cast<unsigned char>(value >> 8), static_cast<unsigned char>(value)};
  return put(bytes, 4);
}

bool OscBundleWriter::put_string(std::string_view s) noexcept {
  static constexpr char kZeros[4] = {0, 0, 0, 0};
  return put(s.data(), s.size()) && put(kZeros, 4 - s.size() % 4);
}

void OscBundleWriter::begin() noexcept {
  size_ = 0;
  ok_ = true;
  put("#bundle", 8);  // with its NUL: 8 bytes
  put_be32(0);        // time tag 1 = "immediately"
  put_be32(1);
}

bool OscBundleWriter::message(std::string_view address, std::string_view types,
                              std::span<const std::int32_t> ints, std::span<const float> floats,
                              std::span<const std::string_view> strings) noexcept {
  if (!ok_) return false;
  const std::size_t size_at = size_;
  if (!put_be32(0)) return false;  // the element's size, patched below
  const std::size_t start = size_;
  put_string(address);
  char tags[32] = {','};
  if (types.size() + 1 >= sizeof tags) return ok_ = false;
  std::memcpy(tags + 1, types.data(), types.size());
  put_string(std::string_view(tags, types.size() + 1));
  std::size_t i = 0, f = 0, s = 0;
  for (const char t : types) {
    if (t == 'i' && i < ints.size()) {
      put_be32(static_cast<std::uint32_t>(ints[i++]));
    } else if (t == 'f' && f < floats.size()) {
      put_be32(std::bit_cast<std::uint32_t>(floats[f++]));
    } else if (t == 's' && s < strings.size()) {
      put_string(strings[s++]);
    } else {
      return ok_ = false;
    }
  }
  if (!ok_) return false;
  const auto length = static_cast<std::uint32_t>(size_ - start);
  const unsigned char bytes[4] = {
      static_cast<unsigned char>(length >> 24), static_cast<unsigned char>(length >> 16),
      static_cast<unsigned char>(length >> 8), static_cast<unsigned char>(length)};
  std::memcpy(buffer_.data() + size_at, bytes, 4);
  return true;
}

}  // namespace duet::net
