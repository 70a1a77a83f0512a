#include "duet/live/source_spec.h"

#include <cmath>
#include <optional>

#include "duet/base/parse_number.h"

namespace duet {

namespace {

Error spec_error(std::string_view text, const std::string& reason) {
  return Error{"--source '" + std::string(text) + "': " + reason};
}

bool parse_port(std::string_view text, std::uint16_t& port) {
  const std::optional<std::uint16_t> value = parse_number<std::uint16_t>(text);
  if (!value || *value == 0) return false;
  port = *value;
  return true;
}

bool parse_finite(std::string_view text, double& value) {
  const std::optional<double> parsed = parse_number<double>(text);
  if (parsed) value = *parsed;
  return parsed.has_value();
}

bool parse_flag(std::string_view text, bool& value) {
  if (text == "1" || text == "true" || text == "yes") {
    value = true;
  } else if (text == "0" || text == "false" || text == "no") {
    value = false;
  } else {
    return false;
  }
  return true;
}

// "[HOST:]PORT" or "[V6]:PORT"; host keeps `default_host` when absent.
bool parse_host_port(std::string_view text, std::string& host, std::uint16_t& port) {
  std::string_view port_text = text;
  if (!text.empty() && text.front() == '[') {
    const std::size_t close = text.find(']');
    if (close == std::string_view::npos || close + 1 >= text.size() || text[close + 1] != ':') {
      return false;
    }
    host = std::string(text.substr(1, close - 1));
    port_text = text.substr(close + 2);
  } else if (const std::size_t colon = text.rfind(':'); colon != std::string_view::npos) {
    host = std::string(text.substr(0, colon));
    port_text = text.substr(colon + 1);
    if (host.empty() || host.find(':') != std::string::npos) return false;
  }
  return parse_port(port_text, port);
}

// Applies "key=value&key=value" to the spec; `allowed` names the keys of this kind.
std::optional<std::string> apply_query(std::string_view query, SourceSpec& spec) {
  while (!query.empty()) {
    const std::size_t amp = query.find('&');
    const std::string_view item = query.substr(0, amp);
    query = amp == std::string_view::npos ? std::string_view{} : query.substr(amp + 1);
    if (item.empty()) continue;
    const std::size_t eq = item.find('=');
    if (eq == std::string_view::npos) return "option '" + std::string(item) + "' needs a value";
    const std::string_view key = item.substr(0, eq);
    const std::string_view value = item.substr(eq + 1);
    const std::string bad = "bad value '" + std::string(value) + "' for " + std::string(key);
    if (spec.kind == SourceKind::kReplay) {
      if (key == "speed") {
        if (!parse_finite(value, spec.replay.speed) || spec.replay.speed < 0.05 ||
            spec.replay.speed > 20.0) {
          return bad + " (a number from 0.05 to 20)";
        }
        continue;
      }
      if (key == "loop") {
        if (!parse_flag(value, spec.replay.loop)) return bad + " (0 or 1)";
        continue;
      }
      if (key == "start") {
        if (!parse_finite(value, spec.replay.start_s) || spec.replay.start_s < 0.0) {
          return bad + " (seconds >= 0)";
        }
        continue;
      }
      return "unknown option '" + std::string(key) + "' (replay takes speed, loop, start)";
    }
    if (spec.kind == SourceKind::kNeuronTcp || spec.kind == SourceKind::kNeuronUdp) {
      if (key == "reference") {
        if (!parse_flag(value, spec.reference)) return bad + " (0 or 1)";
        continue;
      }
      return "unknown option '" + std::string(key) + "' (neuron takes reference)";
    }
    if (spec.kind == SourceKind::kVmc) {
      return "unknown option '" + std::string(key) + "' (vmc takes no options)";
    }
    return "unknown option '" + std::string(key) + "'";
  }
  return std::nullopt;
}

}  // namespace

const char* source_kind_name(SourceKind kind) {
  switch (kind) {
    case SourceKind::kReplay:
      return "replay";
    case SourceKind::kNeuronTcp:
      return "neuron-tcp";
    case SourceKind::kNeuronUdp:
      return "neuron-udp";
    case SourceKind::kWebSocket:
      return "ws";
    case SourceKind::kXr:
      return "xr";
    case SourceKind::kVmc:
      return "vmc";
  }
  return "?";
}

Result<SourceSpec> parse_source_spec(std::string_view text) {
  SourceSpec spec;
  const std::size_t colon = text.find(':');
  const std::string_view kind = text.substr(0, colon);
  std::string_view rest =
      colon == std::string_view::npos ? std::string_view{} : text.substr(colon + 1);
  if (kind == "ws") {
    spec.kind = SourceKind::kWebSocket;
    if (colon != std::string_view::npos && rest.empty()) {
      return spec_error(text, "expected ws or ws:SKELETON.bvh");
    }
    spec.path = std::string(rest);
    return spec;
  }
  if (kind == "xr") {
    if (colon != std::string_view::npos) return spec_error(text, "xr takes nothing after it");
    spec.kind = SourceKind::kXr;
    return spec;
  }
  if (kind == "replay") {
    spec.kind = SourceKind::kReplay;
  } else if (kind == "neuron-tcp") {
    spec.kind = SourceKind::kNeuronTcp;
  } else if (kind == "neuron-udp") {
    spec.kind = SourceKind::kNeuronUdp;
  } else if (kind == "vmc") {
    spec.kind = SourceKind::kVmc;
  } else {
    return spec_error(text, "unknown source kind '" + std::string(kind) +
                                "' (replay:FILE.bvh, neuron-tcp:HOST:PORT, neuron-udp:PORT, ws, "
                                "xr, vmc:PORT)");
  }
  // The query starts at the last '?' so a file name may hold one.
  const std::size_t question = rest.rfind('?');
  const std::string_view query =
      question == std::string_view::npos ? std::string_view{} : rest.substr(question + 1);
  rest = rest.substr(0, question);
  if (auto problem = apply_query(query, spec)) return spec_error(text, *problem);

  if (spec.kind == SourceKind::kReplay) {
    if (rest.empty()) return spec_error(text, "expected replay:FILE.bvh");
    spec.path = std::string(rest);
    return spec;
  }
  spec.host = "127.0.0.1";
  if (spec.kind == SourceKind::kVmc && colon == std::string_view::npos) {
    spec.port = kVmcDefaultPort;
    return spec;
  }
  if (!parse_host_port(rest, spec.host, spec.port)) {
    if (spec.kind == SourceKind::kVmc) {
      return spec_error(text, "expected vmc, vmc:PORT or vmc:ADDR:PORT (e.g. vmc:39539)");
    }
    return spec_error(text, spec.kind == SourceKind::kNeuronTcp
                                ? "expected neuron-tcp:HOST:PORT (e.g. neuron-tcp:127.0.0.1:7001)"
                                : "expected neuron-udp:PORT or neuron-udp:ADDR:PORT");
  }
  return spec;
}

}  // namespace duet
