#include "duet/net/osc_output.h"

#include <array>
#include <boost/asio/ip/udp.hpp>
#include <optional>

#include "duet/base/parse_number.h"
#include "duet/net/osc_writer.h"

namespace duet::net {

namespace asio = boost::asio;
using boost::system::error_code;

bool parse_osc_target(const std::string& text, std::string& host, std::uint16_t& port) {
  std::string_view port_text;
  if (!text.empty() && text.front() == '[') {
    const std::size_t close = text.find(']');
    if (close == std::string::npos || close + 1 >= text.size() || text[close + 1] != ':') {
      return false;
    }
    host = text.substr(1, close - 1);
    port_text = std::string_view(text).substr(close + 2);
  } else {
    const std::size_t colon = text.rfind(':');
    if (colon == std::string::npos || colon == 0) return false;
    host = text.substr(0, colon);
    if (host.find(':') != std::string::npos) return false;  // a bare IPv6 address needs brackets
    port_text = std::string_view(text).substr(colon + 1);
  }
  const std::optional<std::uint16_t> value = parse_number<std::uint16_t>(port_text);
  if (!value || *value == 0 || host.empty()) return false;
  port = *value;
  return true;
}

struct OscOutput::Impl {
  explicit Impl(asio::io_context& io) : socket(io) {}
  asio::ip::udp::socket socket;
  asio::ip::udp::endpoint to;
  std::string where;
  OscBundleWriter writer{2048};
  long long sent = 0;
  long long dropped = 0;
};

OscOutput::OscOutput(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
OscOutput::~OscOutput() = default;

Result<std::unique_ptr<OscOutput>> OscOutput::open(asio::io_context& io, const std::string& host,
                                                   std::uint16_t port) {
  auto impl = std::make_unique<Impl>(io);
  impl->where = host + ":" + std::to_string(port);
  error_code ec;
  asio::ip::udp::resolver resolver(io);
  const auto results = resolver.resolve(host, std::to_string(port), ec);
  if (ec || results.empty()) {
    return Error{"--osc-out " + impl->where + ": cannot resolve " + host + ": " +
                 (ec ? ec.message() : std::string("no address"))};
  }
  impl->to = results.begin()->endpoint();
  impl->socket.open(impl->to.protocol(), ec);
  if (!ec) impl->socket.non_blocking(true, ec);
  if (ec) return Error{"--osc-out " + impl->where + ": cannot open a UDP socket: " + ec.message()};
  return std::unique_ptr<OscOutput>(new OscOutput(std::move(impl)));
}

void OscOutput::send(const LiveOutput& out, const LiveLoop& loop, long long seq) noexcept {
  const FollowResult& f = out.follow;
  const DuetLibrary& library = loop.library();
  const bool have_take = f.take >= 0 && f.take < static_cast<int>(library.takes().size());
  const std::string_view name =
      have_take ? std::string_view(library.takes()[static_cast<std::size_t>(f.take)].name)
                : std::string_view();
  const double fps = library.frame_rate();
  const float time_in_take =
      f.frame_in_take >= 0 && fps > 0.0 ? static_cast<float>(f.frame_in_take / fps) : 0.0f;
  auto i = [](long long v) { return std::array<std::int32_t, 1>{static_cast<std::int32_t>(v)}; };
  auto fl = [](float v) { return std::array<float, 1>{v}; };

  OscBundleWriter& w = impl_->writer;
  w.begin();
  w.message("/duet/seq", "i", i(seq));
  w.message("/duet/take", "i", i(f.take));
  const std::array<std::string_view, 1> names = {name};
  w.message("/duet/take/name", "s", {}, {}, names);
  w.message("/duet/frame", "i", i(f.frame_in_take));
  w.message("/duet/time", "f", {}, fl(time_in_take));
  w.message("/duet/confidence", "f", {}, fl(f.confidence));
  w.message("/duet/tempo", "f", {}, fl(f.tempo));
  w.message("/duet/jumped", "i", i(f.jumped ? 1 : 0));
  w.message("/duet/lost", "i", i(f.lost ? 1 : 0));
  w.message("/duet/contact/left", "i", i(out.contact_left ? 1 : 0));
  w.message("/duet/contact/right", "i", i(out.contact_right ? 1 : 0));
  if (!w.ok()) {
    ++impl_->dropped;  // a take name too long for the buffer
    return;
  }
  error_code ec;
  const std::span<const char> bytes = w.bytes();
  impl_->socket.send_to(asio::buffer(bytes.data(), bytes.size()), impl_->to, 0, ec);
  if (ec) {
    ++impl_->dropped;
  } else {
    ++impl_->sent;
  }
}

long long OscOutput::sent() const noexcept { return impl_->sent; }
long long OscOutput::dropped() const noexcept { return impl_->dropped; }
std::string OscOutput::where() const { return impl_->where; }

}  // namespace duet::net
