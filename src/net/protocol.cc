#include "duet/net/protocol.h"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <nlohmann/json.hpp>

namespace duet::net {

namespace {

using nlohmann::json;

json skeleton_json(const Skeleton& skeleton, const JointRoles& roles) {
  json joints = json::array();
  for (const Joint& joint : skeleton.joints) {
    joints.push_back({{"name", joint.name},
                      {"parent", joint.parent},
                      {"offset", {joint.offset.x(), joint.offset.y(), joint.offset.z()}},
                      {"end_site", joint.end_site}});
  }
  json role_map = json::object();
  for (int r = 0; r < kRoleCount; ++r) {
    const int j = roles.joints[static_cast<std::size_t>(r)];
    if (j >= 0 && j < skeleton.joint_count())
      role_map[std::string(role_name(static_cast<Role>(r)))] = j;
  }
  return {{"joints", std::move(joints)}, {"roles", std::move(role_map)}};
}

json corrections_json(const PartnerParams& params) {
  json c = json::object();
  for (const std::string_view name : kCorrectionNames) {
    c[std::string(name)] = correction_enabled(params, name);
  }
  return c;
}

const char* side_name(Side side) { return side == Side::kLeft ? "left" : "right"; }

json latency_json(const LatencySummary& s, bool with_count) {
  json j = {{"p50", s.p50}, {"p99", s.p99}, {"max", s.max}};
  if (with_count) j["count"] = s.count;
  return j;
}

// Fixed-point with `decimals` digits, trailing zeros trimmed; null for NaN/inf (JSON has neither).
void append_number(std::string& out, double value, int decimals) {
  static constexpr double kScale[] = {1.0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6};
  static constexpr long long kPow10[] = {1, 10, 100, 1000, 10000, 100000, 1000000};
  if (!std::isfinite(value)) {
    out += "null";
    return;
  }
  const double scaled = std::round(value * kScale[decimals]);
  if (std::abs(scaled) >= 9e15) {
    fmt::format_to(std::back_inserter(out), "{}", value);
    return;
  }
  long long n = static_cast<long long>(scaled);
  if (n < 0) {
    out += '-';
    n = -n;
  }
  char buffer[32];
  const long long integer = n / kPow10[decimals];
  long long fraction = n % kPow10[decimals];
  auto result = std::to_chars(buffer, buffer + sizeof buffer, integer);
  out.append(buffer, static_cast<std::size_t>(result.ptr - buffer));
  if (fraction == 0) return;
  int digits = decimals;
  while (fraction % 10 == 0) {
    fraction /= 10;
    --digits;
  }
  out += '.';
  // Leading zeros of the fraction: 0.0012 has fraction 12 with 4 digits.
  result = std::to_chars(buffer, buffer + sizeof buffer, fraction);
  const auto written = static_cast<int>(result.ptr - buffer);
  out.append(static_cast<std::size_t>(digits - written), '0');
  out.append(buffer, static_cast<std::size_t>(written));
}

void append_int(std::string& out, long long value) {
  char buffer[24];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, static_cast<std::size_t>(result.ptr - buffer));
}

void append_bool(std::string& out, bool value) { out += value ? "true" : "false"; }

void append_pose(std::string& out, std::span<const Vec3> positions,
                 std::span<const Quat> rotations) {
  out += "{\"positions\":[";
  for (std::size_t j = 0; j < positions.size(); ++j) {
    if (j) out += ',';
    out += '[';
    append_number(out, positions[j].x(), 4);
    out += ',';
    append_number(out, positions[j].y(), 4);
    out += ',';
    append_number(out, positions[j].z(), 4);
    out += ']';
  }
  out += "],\"rotations\":[";
  for (std::size_t j = 0; j < rotations.size(); ++j) {
    if (j) out += ',';
    out += '[';
    append_number(out, rotations[j].w(), 5);
    out += ',';
    append_number(out, rotations[j].x(), 5);
    out += ',';
    append_number(out, rotations[j].y(), 5);
    out += ',';
    append_number(out, rotations[j].z(), 5);
    out += ']';
  }
  out += "]}";
}

// Nesting depth and number of values (commas and openings, a close upper bound) of JSON text,
// ignoring what is inside strings. Cheap: one pass, no allocation.
struct JsonShape {
  int depth = 0;
  std::size_t values = 0;
};
JsonShape json_shape(std::string_view text) {
  JsonShape shape;
  int depth = 0;
  bool in_string = false, escape = false;
  for (const char c : text) {
    if (in_string) {
      if (escape) {
        escape = false;
      } else if (c == '\\') {
        escape = true;
      } else if (c == '"') {
        in_string = false;
      }
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      shape.depth = std::max(shape.depth, ++depth);
      ++shape.values;
    } else if (c == ']' || c == '}') {
      --depth;
    } else if (c == ',') {
      ++shape.values;
    }
  }
  return shape;
}

bool get_number(const json& value, double& out) {
  if (!value.is_number()) return false;
  out = value.get<double>();
  return std::isfinite(out);
}

}  // namespace

std::string make_hello(const LiveLoop& loop, const std::string& source_description,
                       std::string_view source_kind, const DevicePointOffsets* device_offsets) {
  const DuetLibrary& library = loop.library();
  json takes = json::array();
  for (std::size_t t = 0; t < library.takes().size(); ++t) {
    const DuetTake& take = library.takes()[t];
    const HandContacts& contacts = loop.partner_model(static_cast<int>(t)).contacts();
    json intervals = json::array();
    for (int pair = 0; pair < kHandPairCount; ++pair) {
      for (const ContactInterval& c : contacts.intervals(pair)) {
        intervals.push_back({{"user_hand", side_name(template_side(pair))},
                             {"partner_hand", side_name(response_side(pair))},
                             {"start", c.begin_frame},
                             {"end", c.end_frame}});
      }
    }
    takes.push_back({{"name", take.name},
                     {"frames", take.template_motion.clip.frame_count()},
                     {"contacts", std::move(intervals)}});
  }
  json hello = {
      {"type", "hello"},
      {"version", kProtocolVersion},
      {"role", dancer_role_name(loop.role())},
      {"fps", library.frame_rate()},
      {"user_skeleton", skeleton_json(*loop.user().skeleton, loop.user().roles)},
      {"partner_skeleton",
       skeleton_json(*loop.partner_skeleton(), loop.partner_model(0).response_roles())},
      {"takes", std::move(takes)},
      {"corrections", corrections_json(loop.params())},
      {"source", source_description},
      {"source_kind", source_kind},
  };
  if (device_offsets) {
    const Vec3& eyes = device_offsets->eyes_m;
    hello["device_offsets"] = {{"eyes_m", {eyes.x(), eyes.y(), eyes.z()}},
                               {"grip_m", device_offsets->grip_m}};
  }
  return hello.dump(-1, ' ', false, json::error_handler_t::replace);
}

void format_frame(const LiveOutput& output, const PartnerParams& params, std::int64_t latency_us,
                  std::string& text, long long seq) {
  text.clear();
  const FollowResult& f = output.follow;
  text += "{\"type\":\"frame\",\"seq\":";
  append_int(text, seq >= 0 ? seq : output.seq);
  text += ",\"time_s\":";
  append_number(text, output.time_s, 4);
  text += ",\"follower\":{\"take\":";
  append_int(text, f.take);
  text += ",\"template_frame\":";
  append_int(text, f.frame_in_take);
  text += ",\"confidence\":";
  append_number(text, f.confidence, 3);
  text += ",\"jumped\":";
  append_bool(text, f.jumped);
  text += ",\"lost\":";
  append_bool(text, f.lost);
  text += ",\"in_pause\":";
  append_bool(text, f.in_pause);
  text += "},\"user\":";
  append_pose(text, output.user_positions_ws, output.user_rotations_ws);
  text += ",\"partner\":";
  append_pose(text, output.partner_positions_ws, output.partner_rotations_ws);
  text += ",\"corrections\":{";
  for (const std::string_view name : kCorrectionNames) {
    if (name != kCorrectionNames[0]) text += ',';
    text += '"';
    text += name;
    text += "\":";
    append_bool(text, correction_enabled(params, name));
  }
  text += "},\"contact\":{\"left\":";
  append_bool(text, output.contact_left);
  text += ",\"right\":";
  append_bool(text, output.contact_right);
  text += "},\"latency_us\":";
  append_int(text, latency_us);
  text += '}';
}

std::string make_stats(const StatsSnapshot& s) {
  json stats = {
      {"type", "stats"},
      {"frames", s.frames},
      {"clients", s.clients},
      {"dropped", s.dropped},
      {"rejected", s.rejected},
      {"rate_hz", std::round(s.rate_hz * 10.0) / 10.0},
      {"latency_us", latency_json(s.latency, true)},
      {"latency_total_us", latency_json(s.latency_total, true)},
      {"loop_us", latency_json(s.loop, false)},
      {"source",
       {{"frames", s.source.frames},
        {"rejected", s.source.rejected},
        {"dropped", s.source.dropped}}},
      {"recording", {{"frames", s.recorded}, {"lost", s.record_lost}}},
  };
  if (s.calibration_offset) {
    stats["advice"] = {
        {"calibrate", {{"rig_offset", std::round(*s.calibration_offset * 1000.0) / 1000.0}}}};
  }
  return stats.dump(-1, ' ', false, json::error_handler_t::replace);
}

std::string make_error(std::string_view reason) {
  // Replace invalid UTF-8 (a reason may quote client input) instead of throwing.
  return json{{"type", "error"}, {"reason", std::string(reason)}}.dump(
      -1, ' ', false, json::error_handler_t::replace);
}

std::string make_replay_state(const ReplayState& state) {
  const json message = {{"type", "replay_state"},
                        {"paused", state.paused},
                        {"speed", state.speed},
                        {"position_s", std::round(state.position_s * 1000.0) / 1000.0},
                        {"duration_s", std::round(state.duration_s * 1000.0) / 1000.0},
                        {"loop", state.loop}};
  return message.dump();
}

namespace {

// {"type": "xr_pose", "time_s": T, "head": {"position": [x, y, z], "orientation": [w, x, y, z]},
//  "left": {...}, "right": {...}}: a headset's and its controllers' poses (docs/protocol.md).
std::optional<std::string> parse_xr_pose(const json& doc, ClientMessage& message) {
  message.type = ClientMessage::Type::kXrPose;
  message.time_s = std::nan("");
  if (const auto time = doc.find("time_s"); time != doc.end()) {
    if (!get_number(*time, message.time_s)) return "xr_pose: \"time_s\" must be a finite number";
  }
  constexpr std::array<const char*, 3> kPoints = {"head", "left", "right"};
  for (std::size_t p = 0; p < kPoints.size(); ++p) {
    const auto point = doc.find(kPoints[p]);
    if (point == doc.end() || !point->is_object()) {
      return fmt::format("xr_pose: needs \"{}\": {{\"position\": [x, y, z], \"orientation\": "
                         "[w, x, y, z]}}",
                         kPoints[p]);
    }
    const auto position = point->find("position");
    const auto orientation = point->find("orientation");
    if (position == point->end() || !position->is_array() || position->size() != 3 ||
        orientation == point->end() || !orientation->is_array() || orientation->size() != 4) {
      return fmt::format("xr_pose: \"{}\" needs \"position\": [x, y, z] and \"orientation\": "
                         "[w, x, y, z]",
                         kPoints[p]);
    }
    for (std::size_t k = 0; k < 3; ++k) {
      double v = 0.0;
      if (!get_number((*position)[k], v)) {
        return fmt::format("xr_pose: \"{}\" position must hold finite numbers", kPoints[p]);
      }
      message.point_positions[p][static_cast<int>(k)] = v;
    }
    for (std::size_t k = 0; k < 4; ++k) {
      if (!get_number((*orientation)[k], message.point_orientations[p * 4 + k])) {
        return fmt::format("xr_pose: \"{}\" orientation must hold finite numbers", kPoints[p]);
      }
    }
  }
  return std::nullopt;
}

}  // namespace

std::optional<std::string> parse_client_message(std::string_view text, ClientMessage& message) {
  if (text.size() > kMaxClientMessageBytes) return "message larger than 1 MiB";
  // Checked before parsing, so no message costs the loop's thread more than a fraction of a
  // millisecond to refuse.
  const JsonShape shape = json_shape(text);
  if (shape.depth > kMaxJsonDepth) return "message nested too deeply";
  if (shape.values > kMaxJsonValues) return "message holds too many values";
  json doc = json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded()) return "not valid JSON";
  if (!doc.is_object()) return "a message must be a JSON object";
  const auto type_it = doc.find("type");
  if (type_it == doc.end() || !type_it->is_string()) return "a message needs a string \"type\"";
  const std::string& type = type_it->get_ref<const std::string&>();

  if (type == "set") {
    const auto correction = doc.find("correction");
    const auto enabled = doc.find("enabled");
    if (correction == doc.end() || !correction->is_string()) {
      return "set: needs \"correction\" (" + correction_names_list() + ")";
    }
    if (enabled == doc.end() || !enabled->is_boolean()) return "set: needs \"enabled\": true|false";
    const std::string& name = correction->get_ref<const std::string&>();
    PartnerParams probe;
    if (!set_correction(probe, name, true)) {
      return "unknown correction '" + name.substr(0, 64) + "' (" + correction_names_list() + ")";
    }
    message.type = ClientMessage::Type::kSet;
    message.correction = name;
    message.enabled = enabled->get<bool>();
    return std::nullopt;
  }
  if (type == "role") {
    const auto role = doc.find("role");
    if (role == doc.end() || !role->is_string() ||
        !parse_dancer_role(role->get_ref<const std::string&>(), message.role)) {
      return "role: needs \"role\": \"leader\" or \"partner\"";
    }
    message.type = ClientMessage::Type::kRole;
    return std::nullopt;
  }
  if (type == "reset") {
    message.type = ClientMessage::Type::kReset;
    return std::nullopt;
  }
  if (type == "head_height") {
    // The range of duet serve --head-height; 0 goes back to learning it.
    const auto metres = doc.find("metres");
    double value = 0.0;
    if (metres == doc.end() || !get_number(*metres, value) ||
        (value != 0.0 &&
         !(value >= kHeadPointHeightRangeM[0] && value <= kHeadPointHeightRangeM[1]))) {
      return fmt::format(
          "head_height: needs \"metres\": the headset's height standing, {:g} to {:g} (0: learn "
          "it)",
          kHeadPointHeightRangeM[0], kHeadPointHeightRangeM[1]);
    }
    message.type = ClientMessage::Type::kHeadHeight;
    message.head_height_m = value;
    return std::nullopt;
  }
  if (type == "arms_forward") {
    message.type = ClientMessage::Type::kArmsForward;
    message.forget_arms_forward = false;
    if (const auto forget = doc.find("forget"); forget != doc.end()) {
      if (!forget->is_boolean()) return "arms_forward: \"forget\" must be true or false";
      message.forget_arms_forward = forget->get<bool>();
    }
    return std::nullopt;
  }
  if (type == "pose") {
    message.type = ClientMessage::Type::kPose;
    message.time_s = std::nan("");
    if (const auto time = doc.find("time_s"); time != doc.end()) {
      if (!get_number(*time, message.time_s)) return "pose: \"time_s\" must be a finite number";
    }
    const auto root = doc.find("root");
    if (root == doc.end() || !root->is_array() || root->size() != 3) {
      return "pose: needs \"root\": [x, y, z] in metres";
    }
    for (std::size_t k = 0; k < 3; ++k) {
      double v = 0.0;
      if (!get_number((*root)[k], v)) return "pose: \"root\" must hold 3 finite numbers";
      message.root[static_cast<int>(k)] = v;
    }
    const auto rotations = doc.find("rotations");
    if (rotations == doc.end() || !rotations->is_array()) {
      return "pose: needs \"rotations\": [[w, x, y, z], ...], one per joint";
    }
    message.rotations.clear();
    message.rotations.reserve(rotations->size() * 4);
    for (const json& q : *rotations) {
      if (!q.is_array() || q.size() != 4) return "pose: each rotation must be [w, x, y, z]";
      for (const json& v : q) {
        double value = 0.0;
        if (!get_number(v, value)) return "pose: rotations must hold finite numbers";
        message.rotations.push_back(value);
      }
    }
    return std::nullopt;
  }
  if (type == "xr_pose") return parse_xr_pose(doc, message);
  if (type == "replay") {
    message.type = ClientMessage::Type::kReplay;
    message.replay_paused.reset();
    message.replay_seek_s.reset();
    message.replay_speed.reset();
    if (const auto paused = doc.find("paused"); paused != doc.end()) {
      if (!paused->is_boolean()) return "replay: \"paused\" must be true or false";
      message.replay_paused = paused->get<bool>();
    }
    if (const auto seek = doc.find("seek_s"); seek != doc.end()) {
      double value = 0.0;
      if (!get_number(*seek, value)) return "replay: \"seek_s\" must be a finite number";
      message.replay_seek_s = value;
    }
    if (const auto speed = doc.find("speed"); speed != doc.end()) {
      double value = 0.0;
      if (!get_number(*speed, value) || value < kReplayMinSpeed || value > kReplayMaxSpeed) {
        return fmt::format("replay: \"speed\" must be a number from {:g} to {:g}", kReplayMinSpeed,
                           kReplayMaxSpeed);
      }
      message.replay_speed = value;
    }
    if (!message.replay_paused && !message.replay_seek_s && !message.replay_speed) {
      return "replay: needs \"paused\", \"seek_s\" or \"speed\"";
    }
    return std::nullopt;
  }
  return "unknown message type '" + type.substr(0, 64) + "' (set, role, reset, pose, xr_pose, replay)";
}

}  // namespace duet::net
