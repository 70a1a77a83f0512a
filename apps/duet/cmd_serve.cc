// duet serve --pair LEADER PARTNER [...] --source SPEC [--http ADDR:PORT] [--web DIR] [--record
// DIR] Runs the live loop at the rate frames arrive and serves the viewer. See docs/serve.md.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <filesystem>
#include <optional>
#include <random>

#include "commands.h"
#include "duet/base/parse_number.h"
#include "duet/io/points_csv.h"
#include "duet/live/live_loop.h"
#include "duet/live/source_neuron.h"
#include "duet/live/source_pose.h"
#include "duet/live/source_replay.h"
#include "duet/live/source_spec.h"
#include "duet/live/source_vmc.h"
#include "duet/motion/head_hands.h"
#include "duet/net/live_server.h"
#include "duet/net/osc_output.h"
#include "input_points.h"
#include "library_options.h"
#include "number_checks.h"
#include "partner_options.h"
#include "tracker_options.h"

namespace duet::app {

namespace {

namespace fs = std::filesystem;

struct ServeArgs {
  LibraryArgs library;
  TrackerArgs tracker;
  PartnerArgs partner;
  std::string source = "ws";
  std::string source_skeleton;
  std::optional<double> source_fps;
  std::optional<double> source_scale;
  std::string source_map;
  std::string input_points;  // "", "full" or "head,hands"
  std::vector<double> device_offsets_cm;  // empty: typical_headset_offsets for xr, else none
  double head_height_m = 0.0;  // the head point's height standing (--head-height); 0: learnt
  std::string calibration_path;  // --calibration: standing with both arms held forward
  std::string http = "127.0.0.1:8080";
  std::optional<std::string> token;
  std::string web;
  std::string record = "recordings";
  bool no_record = false;
  bool exit_at_end = false;
  double log_interval_s = 5.0;
  int queue_frames = 2;
  std::string priority = "realtime";
  std::string osc_out;
};

void fail(const std::string& message) { fmt::print(stderr, "duet serve: {}\n", message); }

double milliseconds(std::int64_t us) { return static_cast<double>(us) / 1000.0; }

// "ADDR:PORT", "PORT", ":PORT" or "[V6]:PORT".
bool parse_http(const std::string& text, std::string& address, std::uint16_t& port) {
  std::string_view port_text = text;
  address = "127.0.0.1";
  if (!text.empty() && text.front() == '[') {
    const std::size_t close = text.find(']');
    if (close == std::string::npos || close + 1 >= text.size() || text[close + 1] != ':') {
      return false;
    }
    address = text.substr(1, close - 1);
    port_text = std::string_view(text).substr(close + 2);
  } else if (const std::size_t colon = text.rfind(':'); colon != std::string::npos) {
    if (colon > 0) address = text.substr(0, colon);
    port_text = std::string_view(text).substr(colon + 1);
  }
  const std::optional<std::uint16_t> value = parse_number<std::uint16_t>(port_text);
  if (!value) return false;
  port = *value;
  return true;
}

bool is_loopback(const std::string& address) {
  return address == "localhost" || address == "::1" || address.starts_with("127.");
}

// 128 random bits in hex: the control token of a server reachable from the network.
std::string random_token() {
  std::random_device device;  // /dev/urandom on Linux
  std::string token;
  for (int k = 0; k < 4; ++k) token += fmt::format("{:08x}", device());
  return token;
}

// --web, else web/dist in the working directory, else the installed copy beside the binary
// (<prefix>/share/duet/web for <prefix>/bin/duet: `cmake --install`), else web/dist in the
// source tree this binary was built from.
fs::path find_web_dir(const std::string& arg) {
  if (!arg.empty()) return arg;
  std::error_code ec;
  const fs::path here = "web/dist";
  if (fs::is_regular_file(here / "index.html", ec)) return here;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed = (exe.parent_path() / DUET_WEB_DIR_FROM_BINDIR).lexically_normal();
    if (fs::is_regular_file(installed / "index.html", ec)) return installed;
  }
  const fs::path source_tree = fs::path(__FILE__).parent_path().parent_path().parent_path();
  const fs::path built = source_tree / "web" / "dist";
  if (fs::is_regular_file(built / "index.html", ec)) return built;
  return {};
}

MotionLoadOptions source_load_options(const ServeArgs& args, std::optional<double> fps, bool& ok) {
  MotionLoadOptions options;
  options.frame_rate = fps;
  options.metres_per_unit = args.source_scale;
  ok = true;
  if (!args.source_map.empty()) {
    SkeletonMap map;
    std::string error;
    if (!load_skeleton_map(args.source_map, map, error)) {
      fail(error);
      ok = false;
    }
    options.map = map;
  }
  return options;
}

Result<SourceSkeleton> load_source_skeleton(const std::string& path, const ServeArgs& args,
                                            double default_rate) {
  bool ok = false;
  const MotionLoadOptions options = source_load_options(args, args.source_fps, ok);
  if (!ok) return Error{"bad --source-map"};
  Result<LoadedMotion> motion = load_motion({path}, options);
  if (!motion) return motion.error();
  SourceSkeleton skeleton;
  skeleton.skeleton = motion.value().clip.skeleton_ptr();
  skeleton.roles = motion.value().roles;
  skeleton.metres_per_unit = motion.value().metres_per_unit;
  const double file_rate = motion.value().clip.frame_rate();
  skeleton.frame_rate = args.source_fps                                 ? *args.source_fps
                        : (file_rate > 0.0 && std::isfinite(file_rate)) ? file_rate
                                                                        : default_rate;
  return skeleton;
}

// The device offsets taken out of the source's points: the typical headset's for --source xr
// unless --device-offsets-cm says otherwise; a replayed recording's only when given.
DevicePointOffsets taken_out_offsets(SourceKind kind, const ServeArgs& args) {
  if (kind == SourceKind::kXr && args.device_offsets_cm.empty()) return typical_headset_offsets();
  return device_offsets_from_cm(args.device_offsets_cm);
}

Result<std::unique_ptr<FrameSource>> make_source(const SourceSpec& spec, const ServeArgs& args,
                                                 const DuetLibrary& library) {
  switch (spec.kind) {
    case SourceKind::kReplay: {
      // A replayed file is usually a take of the same capture: --fps applies unless
      // --source-fps says otherwise.
      bool ok = false;
      const MotionLoadOptions options =
          source_load_options(args, args.source_fps ? args.source_fps : args.library.fps, ok);
      if (!ok) return Error{"bad --source-map"};
      Result<LoadedMotion> motion = load_motion({spec.path}, options);
      if (!motion) return motion.error();
      if (Status s = take_out_device_offsets(args.device_offsets_cm, motion.value()); !s) {
        return s.error();
      }
      Result<InputPoints> points = choose_input_points(args.input_points, motion.value());
      if (!points) return points.error();
      Result<ReplaySource> replay = ReplaySource::create(std::move(motion).value(), spec.replay,
                                                         fs::path(spec.path).filename().string());
      if (!replay) return replay.error();
      return std::unique_ptr<FrameSource>(
          std::make_unique<ReplaySource>(std::move(replay).value()));
    }
    case SourceKind::kNeuronTcp:
    case SourceKind::kNeuronUdp: {
      if (args.source_skeleton.empty()) {
        return Error{
            "a Perception Neuron source needs --source-skeleton HEADER.bvh (a BVH "
            "exported by Axis for the same skeleton; its motion is ignored)"};
      }
      Result<SourceSkeleton> skeleton = load_source_skeleton(args.source_skeleton, args, 60.0);
      if (!skeleton) return skeleton.error();
      NeuronStreamOptions options;
      options.reference = spec.reference;
      const std::string name =
          fmt::format("Perception Neuron BVH over {} {} {}:{}",
                      spec.kind == SourceKind::kNeuronTcp ? "TCP" : "UDP",
                      spec.kind == SourceKind::kNeuronTcp ? "from" : "on", spec.host, spec.port);
      return std::unique_ptr<FrameSource>(
          std::make_unique<NeuronSource>(std::move(skeleton).value(), options, name));
    }
    case SourceKind::kVmc: {
      // VMC carries the humanoid's bone rotations, not a skeleton of its own: the user's skeleton
      // is the VMC humanoid (duet/live/vmc_humanoid.h).
      if (!args.source_skeleton.empty() || !args.source_map.empty() || args.source_scale) {
        return Error{
            "a vmc source drives the VMC humanoid skeleton: --source-skeleton, --source-map and "
            "--source-scale do not apply"};
      }
      const double rate = args.source_fps ? *args.source_fps : library.frame_rate();
      return std::unique_ptr<FrameSource>(std::make_unique<VmcSource>(
          VmcStreamOptions{}, fmt::format("VMC (OSC over UDP) on {}:{}", spec.host, spec.port),
          rate));
    }
    case SourceKind::kWebSocket: {
      const std::string path = !spec.path.empty() ? spec.path : args.source_skeleton;
      SourceSkeleton skeleton;
      std::string which;
      if (!path.empty()) {
        Result<SourceSkeleton> loaded = load_source_skeleton(path, args, library.frame_rate());
        if (!loaded) return loaded.error();
        skeleton = std::move(loaded).value();
        which = fs::path(path).filename().string();
      } else {
        // Poses in the template's own skeleton (the first take of the user's role).
        const LoadedMotion& t = library.takes()[0].template_motion;
        skeleton.skeleton = t.clip.skeleton_ptr();
        skeleton.roles = t.roles;
        skeleton.metres_per_unit = 1.0;
        skeleton.frame_rate = args.source_fps ? *args.source_fps : library.frame_rate();
        which = "the skeleton of " + library.takes()[0].name;
      }
      return std::unique_ptr<FrameSource>(
          std::make_unique<PoseSource>(std::move(skeleton), PoseSourceOptions{},
                                       "poses from WebSocket clients (" + which + ")"));
    }
    case SourceKind::kXr: {
      SourceSkeleton skeleton{make_head_hands_skeleton(), head_hands_roles(), 1.0,
                              args.source_fps ? *args.source_fps : 72.0};
      PoseSourceOptions options;
      options.device_offsets = taken_out_offsets(SourceKind::kXr, args);
      return std::unique_ptr<FrameSource>(std::make_unique<PoseSource>(
          std::move(skeleton), options,
          "a VR headset and two controllers (xr_pose messages over the WebSocket)"));
    }
  }
  return Error{"unknown source"};
}

// Which points the follower sees: three for the headset source, a three-point recording or
// --input-points head,hands; else the whole body. Decided before the library is built, since its
// templates must give the same points.
Result<InputPoints> serve_input_points(const SourceSpec& spec, const ServeArgs& args) {
  const bool csv = spec.kind == SourceKind::kReplay && is_points_csv_path(spec.path);
  InputPoints asked = InputPoints::kFullBody;
  if (!args.input_points.empty()) parse_input_points(args.input_points, asked);
  if (spec.kind == SourceKind::kXr || csv) {
    if (!args.input_points.empty() && asked == InputPoints::kFullBody) {
      return Error{"--input-points full: the source gives only a head and two hands"};
    }
    return InputPoints::kHeadHands;
  }
  if (!args.device_offsets_cm.empty() && spec.kind != SourceKind::kReplay) {
    return Error{
        "--device-offsets-cm applies to three points (--source xr, or a replayed "
        "three-point recording)"};
  }
  if (asked == InputPoints::kHeadHands && spec.kind != SourceKind::kReplay) {
    return Error{"--input-points head,hands applies to a replayed file (a live body source "
                 "sends the whole body; --source xr sends three points)"};
  }
  return asked;
}

Result<std::unique_ptr<LiveLoop>> make_loop(std::shared_ptr<const DuetLibrary> library,
                                            const TrackerArgs& tracker_args,
                                            const SourceSkeleton& user,
                                            const PartnerParams& params) {
  Result<std::unique_ptr<Tracker>> tracker = make_tracker(tracker_args, *library);
  if (!tracker) return tracker.error();
  Result<LiveLoop> loop =
      LiveLoop::create(std::move(library), user, std::move(tracker).value(), params);
  if (!loop) return loop.error();
  return std::make_unique<LiveLoop>(std::move(loop).value());
}

int run_serve(const ServeArgs& args) {
  Result<SourceSpec> spec = parse_source_spec(args.source);
  if (!spec) {
    fail(spec.error().message);
    return kExitUsage;
  }
  net::LiveServerOptions options;
  if (!args.osc_out.empty() &&
      !net::parse_osc_target(args.osc_out, options.osc_host, options.osc_port)) {
    fail("--osc-out '" + args.osc_out + "': expected HOST:PORT (e.g. 127.0.0.1:9000)");
    return kExitUsage;
  }
  if (!parse_http(args.http, options.server.address, options.server.port)) {
    fail("--http '" + args.http + "': expected ADDR:PORT (e.g. 127.0.0.1:8080)");
    return kExitUsage;
  }

  Result<InputPoints> points = serve_input_points(spec.value(), args);
  if (!points) {
    fail(points.error().message);
    return kExitUsage;
  }
  if (Status s = check_head_height_applies(args.head_height_m, points.value()); !s) {
    fail(s.error().message);
    return kExitUsage;
  }
  if (Status s = check_calibration_applies(args.calibration_path, points.value()); !s) {
    fail(s.error().message);
    return kExitUsage;
  }
  std::optional<BodyCalibration> calibration;
  if (!args.calibration_path.empty()) {
    // A replayed recording's offsets come out of it too; a headset's recording (duet serve
    // --source xr --record) is at the joints already.
    Result<BodyCalibration> read = read_body_calibration(
        args.calibration_path,
        spec.value().kind == SourceKind::kReplay ? args.device_offsets_cm : std::vector<double>{});
    if (!read) {
      fail(read.error().message);
      return kExitFailure;
    }
    calibration = read.value();
  }
  FeatureSpec features;
  features.input_points = points.value();
  std::optional<DuetLibrary> loaded = load_library(args.library, "serve", features);
  if (!loaded) return kExitFailure;
  auto library = std::make_shared<const DuetLibrary>(std::move(*loaded));

  Result<std::unique_ptr<FrameSource>> source = make_source(spec.value(), args, *library);
  if (!source) {
    fail(source.error().message);
    return kExitFailure;
  }
  SourceSkeleton user = source.value()->source_skeleton();
  user.head_height_m =
      head_joint_height_m(args.head_height_m, taken_out_offsets(spec.value().kind, args));
  if (calibration) {
    if (args.head_height_m == 0.0) user.head_height_m = calibration->head_height_m;
    user.arms_forward = calibration->arms_forward;
  }

  const PartnerParams params = make_partner_params(args.partner);
  Result<std::unique_ptr<LiveLoop>> loop = make_loop(library, args.tracker, user, params);
  if (!loop) {
    fail(loop.error().message);
    return kExitFailure;
  }

  // The other role is built on demand (a `role` message), on a background thread.
  net::LoopFactory factory =
      [args, user, features](DancerRole role,
                             const PartnerParams& p) -> Result<std::unique_ptr<LiveLoop>> {
    Result<LibrarySetup> setup = resolve_library(args.library, features);
    if (!setup) return setup.error();
    setup.value().options.role = role;
    Result<DuetLibrary> other = DuetLibrary::load(setup.value().pairs, setup.value().options);
    if (!other) return other.error();
    return make_loop(std::make_shared<const DuetLibrary>(std::move(other).value()), args.tracker,
                     user, p);
  };

  // Anyone who can reach a non-loopback address could steer everybody's session: control then
  // needs a token, which only the printed address carries.
  if (args.token) {
    options.server.control_token = *args.token;
  } else if (!is_loopback(options.server.address)) {
    options.server.control_token = random_token();
  }
  options.server.web_dir = find_web_dir(args.web);
  options.server.max_queued_frames = args.queue_frames;
  options.record_dir = args.no_record ? std::string() : args.record;
  options.exit_at_end = args.exit_at_end;
  options.log_interval_s = args.log_interval_s;
  options.realtime = args.priority == "realtime";

  const std::string description = source.value()->describe();
  net::LiveServer server(options, spec.value(), std::move(source).value(), std::move(loop).value(),
                         factory);
  if (Status s = server.start(); !s) {
    fail(s.error().message);
    return kExitFailure;
  }
  if (!is_loopback(options.server.address)) {
    fail("warning: listening on " + options.server.address +
         ": anyone who can reach this machine can watch; only the printed address (with its "
         "token) can control");
  }
  if (server.web_root() == nullptr) {
    fail(args.web.empty()
             ? "no viewer found (web/dist): build it with `cd web && npm ci && npm run build` or "
               "pass --web DIR; serving a placeholder page"
             : "--web " + args.web + " is not a directory; serving a placeholder page");
  }
  const std::string host = options.server.address.find(':') != std::string::npos
                               ? "[" + options.server.address + "]"
                               : options.server.address;
  fmt::print(stderr, "duet serve: source: {}\n", description);
  if (server.web_root() != nullptr) {
    fmt::print(stderr, "duet serve: viewer files from {}\n", server.web_root()->string());
  }
  // The one line on stdout, for people and for scripts that start the server on port 0.
  const std::string query =
      options.server.control_token.empty() ? "" : "?token=" + options.server.control_token;
  fmt::print("duet serve: viewer at http://{}:{}/{} (WebSocket ws://{}:{}/ws{})\n", host,
             server.port(), query, host, server.port(), query);
  std::fflush(stdout);

  const Status status = server.run();
  const net::ServeSummary& summary = server.summary();
  fmt::print(
      stderr,
      "duet serve: served {} frames to {} client(s); arrival->sent p50 {:.2f} ms, p99 {:.2f} "
      "ms, max {:.2f} ms; {} dropped for slow clients, {} messages rejected\n",
      summary.frames, summary.clients_seen, milliseconds(summary.latency_total.p50),
      milliseconds(summary.latency_total.p99), milliseconds(summary.latency_total.max),
      summary.dropped, summary.rejected);
  if (!options.osc_host.empty()) {
    fmt::print(stderr, "duet serve: OSC out: {} bundles sent, {} dropped\n", summary.osc_sent,
               summary.osc_dropped);
  }
  if (!summary.recordings.empty()) {
    fmt::print(stderr, "duet serve: recorded {} frames{}: {}\n", summary.recorded,
               summary.record_lost ? fmt::format(" ({} lost)", summary.record_lost) : "",
               fmt::join(summary.recordings, ", "));
  }
  if (!status) {
    fail(status.error().message);
    return kExitFailure;
  }
  return kExitOk;
}

}  // namespace

Command register_serve(CLI::App& app) {
  auto args = std::make_shared<ServeArgs>();
  add_library_options(app, args->library);
  add_tracker_options(app, args->tracker);
  add_partner_options(app, args->partner);
  app.add_option("--source", args->source,
                 "Where the user's motion comes from: replay:FILE.bvh[?speed=S&loop=1&start=SEC], "
                 "neuron-tcp:HOST:PORT, neuron-udp:[ADDR:]PORT, ws[:SKELETON.bvh], "
                 "vmc[:[ADDR:]PORT] (VMC protocol over UDP from XR Animator, SlimeVR, VSeeFace, "
                 "Warudo; default port 39539; docs/vmc.md), xr (a VR headset and controllers "
                 "from the viewer's VR session); replay also plays a three-point CSV")
      ->capture_default_str();
  app.add_option("--input-points", args->input_points, kInputPointsHelp)
      ->check(input_points_choice(true));
  add_head_height_option(app, args->head_height_m);
  add_calibration_option(app, args->calibration_path);
  add_device_offsets_option(app, args->device_offsets_cm,
                            "Taken out before following: --source xr default 6,6,7 (a typical "
                            "headset user; 0,0,0 leaves the points as sent), a replayed "
                            "three-point recording default none");
  app.add_option("--source-skeleton", args->source_skeleton,
                 "BVH whose hierarchy describes the live stream (neuron; ws without a skeleton)")
      ->check(CLI::ExistingFile);
  app.add_option("--source-fps", args->source_fps,
                 "Frame rate of the source (replay: default --fps, else the file's; live: the "
                 "rate recordings are written at)")
      ->check(fps_check());
  app.add_option("--source-scale", args->source_scale,
                 "Metres per unit of the source (default: known per skeleton convention)")
      ->check(scale_check());
  app.add_option("--source-map", args->source_map,
                 "Skeleton map JSON for the source's joint names (docs/skeleton-maps.md)")
      ->check(CLI::ExistingFile);
  app.add_option("--osc-out", args->osc_out,
                 "Send the follower's state (take, frame, time, confidence, tempo, jumped, lost, "
                 "contacts) as OSC over UDP to HOST:PORT, one bundle per frame (docs/osc.md)");
  app.add_option("--http", args->http,
                 "Address and port to serve on; 0 as port picks a free one. Loopback unless "
                 "told otherwise")
      ->capture_default_str();
  app.add_option("--token", args->token,
                 "Clients must connect with ?token=TOKEN to send control messages (set, reset, "
                 "role, ...); default: a random token when --http is not loopback, none on "
                 "loopback")
      ->check(CLI::Validator(
          [](std::string& value) -> std::string {
            const bool ok = !value.empty() && value.size() <= 128 &&
                            value.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRS"
                                                    "TUVWXYZ0123456789-_.~") == std::string::npos;
            return ok ? std::string() : "1 to 128 letters, digits, '-', '_', '.' or '~'";
          },
          "TOKEN"));
  app.add_option("--web", args->web,
                 "Directory of the viewer's files (default: web/dist here, else the installed "
                 "share/duet/web beside bin/duet, else web/dist in the source tree)");
  app.add_option("--record", args->record, "Directory for the session's recordings")
      ->capture_default_str();
  app.add_flag("--no-record", args->no_record, "Do not record the session");
  app.add_flag("--exit-at-end", args->exit_at_end, "Stop when a replay without loop ends");
  app.add_option("--log-interval", args->log_interval_s,
                 "Seconds between latency log lines (0: none)")
      ->check(non_negative_check())
      ->capture_default_str();
  app.add_option("--queue-frames", args->queue_frames,
                 "Frames queued per viewer before the oldest is dropped")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  app.add_option("--priority", args->priority,
                 "Scheduling of the loop's thread: realtime (SCHED_FIFO when permitted, else a "
                 "higher nice value) or normal")
      ->check(CLI::IsMember({"realtime", "normal"}))
      ->capture_default_str();
  return [args] { return run_serve(*args); };
}

}  // namespace duet::app
