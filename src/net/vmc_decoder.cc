#include "duet/net/vmc_decoder.h"

#include <lo/lo.h>

#include <cstdint>
#include <cstring>
#include <string_view>

namespace duet::net {

namespace {

// Bundles in bundles deeper than this are rejected (no sender nests; a crafted packet must not
// recurse without bound).
constexpr int kMaxBundleDepth = 4;

std::uint32_t read_be32(const char* p) {
  const auto* u = reinterpret_cast<const unsigned char*>(p);
  return (std::uint32_t{u[0]} << 24) | (std::uint32_t{u[1]} << 16) | (std::uint32_t{u[2]} << 8) |
         std::uint32_t{u[3]};
}

bool is_bundle(const char* data, std::size_t size) {
  return size >= 8 && std::memcmp(data, "#bundle\0", 8) == 0;
}

// Reads arguments [first, first + count) as numbers ('f' or 'd'); false if any is not one.
// Copied byte-wise: in an OSC message a double is only 4-byte aligned.
bool numbers(const char* types, lo_arg** argv, int first, int count, double* out) {
  for (int k = 0; k < count; ++k) {
    const char t = types[first + k];
    const char* bytes = reinterpret_cast<const char*>(argv[first + k]);
    if (t == 'f') {
      float f = 0.0f;
      std::memcpy(&f, bytes, sizeof f);
      out[k] = static_cast<double>(f);
    } else if (t == 'd') {
      std::memcpy(&out[k], bytes, sizeof(double));
    } else {
      return false;
    }
  }
  return true;
}

// "s" followed by 7 numbers (position, then rotation x y z w), as Root/Pos and Bone/Pos carry.
bool transform(const char* types, int argc, lo_arg** argv, std::string_view& name, Vec3& position,
               Quat& rotation) {
  if (argc < 8 || types[0] != 's') return false;
  double v[7];
  if (!numbers(types, argv, 1, 7, v)) return false;
  name = std::string_view(reinterpret_cast<const char*>(argv[0]));
  position = Vec3(v[0], v[1], v[2]);
  rotation = Quat(v[6], v[3], v[4], v[5]);  // w, x, y, z
  return true;
}

void dispatch(std::string_view path, const char* types, int argc, lo_arg** argv,
              SteadyClock::time_point arrival, VmcSource& source) {
  if (!path.starts_with("/VMC/")) {
    source.reject(VmcReject::kForeign);
    return;
  }
  std::string_view name;
  Vec3 position;
  Quat rotation;
  if (path == "/VMC/Ext/Bone/Pos" || path == "/VMC/Ext/Root/Pos") {
    // Root/Pos may carry 6 more numbers (scale and offset, protocol v2.1): not needed.
    const bool is_bone = path == "/VMC/Ext/Bone/Pos";
    if ((is_bone && argc != 8) || !transform(types, argc, argv, name, position, rotation)) {
      source.reject(VmcReject::kBadArguments);
    } else if (is_bone) {
      source.bone(name, position, rotation);
    } else {
      source.root(position, rotation);
    }
    return;
  }
  if (path == "/VMC/Ext/OK" || path == "/VMC/Ext/T") {
    source.frame_marker(arrival);
    return;
  }
  source.ignore();  // blend shapes, camera, trackers, settings: VMC, but not for the follower
}

void decode_element(char* data, std::size_t size, SteadyClock::time_point arrival,
                    VmcSource& source, int depth) {
  if (is_bundle(data, size)) {
    // "#bundle\0", an 8-byte time tag, then elements: a 4-byte big-endian size and that many
    // bytes, each a message or a bundle, sizes multiples of 4.
    if (depth >= kMaxBundleDepth || size < 16) {
      source.reject(VmcReject::kMalformed);
      return;
    }
    std::size_t at = 16;
    while (at < size) {
      if (size - at < 4) {
        source.reject(VmcReject::kMalformed);
        return;
      }
      const std::size_t length = read_be32(data + at);
      at += 4;
      if (length == 0 || length % 4 != 0 || length > size - at) {
        source.reject(VmcReject::kMalformed);
        return;  // the rest of the bundle cannot be framed
      }
      decode_element(data + at, length, arrival, source, depth + 1);
      at += length;
    }
    return;
  }
  int result = 0;
  lo_message message = lo_message_deserialise(data, size, &result);
  if (message == nullptr) {
    source.reject(VmcReject::kMalformed);
    return;
  }
  // The address is valid (deserialise checked it): the first string of the data.
  const std::string_view path(data, strnlen(data, size));
  const char* types = lo_message_get_types(message);
  const int argc = lo_message_get_argc(message);
  lo_arg** argv = lo_message_get_argv(message);
  if (types == nullptr || (argc > 0 && argv == nullptr)) {
    source.reject(VmcReject::kMalformed);
  } else {
    dispatch(path, types, argc, argv, arrival, source);
  }
  lo_message_free(message);
}

}  // namespace

void decode_vmc_packet(char* data, std::size_t size, SteadyClock::time_point arrival,
                       VmcSource& source) noexcept {
  if (size == 0 || data == nullptr) {
    source.reject(VmcReject::kMalformed);
  } else {
    decode_element(data, size, arrival, source, 0);
  }
  source.end_packet(arrival);
}

}  // namespace duet::net
