#include "duet/net/live_server.h"

#include <fmt/format.h>

#include <atomic>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>
#include <csignal>
#include <ctime>
#include <optional>
#include <thread>

#include "duet/io/atomic_write.h"
#include "duet/io/motion_file.h"
#include "duet/io/points_csv.h"
#include "duet/live/calibration_advice.h"
#include "duet/live/source_neuron.h"
#include "duet/live/source_pose.h"
#include "duet/live/source_replay.h"
#include "duet/live/source_vmc.h"
#include "duet/motion/head_hands.h"
#include "duet/net/neuron_receiver.h"
#include "duet/net/osc_output.h"
#include "duet/net/thread_priority.h"
#include "duet/net/vmc_receiver.h"

namespace duet::net {

namespace asio = boost::asio;
using boost::system::error_code;

namespace {

std::int64_t microseconds(SteadyClock::duration d) {
  return std::chrono::duration_cast<std::chrono::microseconds>(d).count();
}

LatencySummary summarize(const LatencyHistogram& h) {
  return {h.percentile(0.5), h.percentile(0.99), h.max(), h.count()};
}

std::string start_stamp() {
  const std::time_t now = std::time(nullptr);
  std::tm local{};
  localtime_r(&now, &local);
  char buffer[32];
  std::strftime(buffer, sizeof buffer, "%Y%m%d-%H%M%S", &local);
  return buffer;
}

std::string ms(std::int64_t us) { return fmt::format("{:.2f}", static_cast<double>(us) / 1000.0); }

// Frame messages are shared by every client's queue; a buffer is reused once no queue holds it,
// so formatting a frame allocates nothing in the steady state. One thread only.
class MessagePool {
 public:
  std::shared_ptr<std::string> acquire() {
    for (std::size_t k = 0; k < buffers_.size(); ++k) {
      const std::size_t i = (next_ + k) % buffers_.size();
      if (buffers_[i].use_count() == 1) {
        next_ = (i + 1) % buffers_.size();
        return buffers_[i];
      }
    }
    auto buffer = std::make_shared<std::string>();
    buffer->reserve(32 * 1024);
    if (buffers_.size() < kMaxBuffers) buffers_.push_back(buffer);
    return buffer;
  }

 private:
  static constexpr std::size_t kMaxBuffers = 64;
  std::vector<std::shared_ptr<std::string>> buffers_;
  std::size_t next_ = 0;
};

}  // namespace

struct LiveServer::Impl {
  Impl(LiveServerOptions o, SourceSpec s, std::unique_ptr<FrameSource> src,
       std::unique_ptr<LiveLoop> l, LoopFactory f)
      : options(std::move(o)),
        spec(std::move(s)),
        source(std::move(src)),
        loop(std::move(l)),
        factory(std::move(f)),
        io(1),
        server(io, options.server, make_callbacks()),
        replay_timer(io),
        stats_timer(io),
        role_timer(io),
        shutdown_timer(io) {
    if (!options.log) {
      options.log = [](const std::string& line) { fmt::print(stderr, "duet serve: {}\n", line); };
    }
    neuron = dynamic_cast<NeuronSource*>(source.get());
    vmc = dynamic_cast<VmcSource*>(source.get());
    pose = dynamic_cast<PoseSource*>(source.get());
    replay = dynamic_cast<ReplaySource*>(source.get());
    frame.resize(source->source_skeleton().joint_count());
    hello = std::make_shared<const std::string>(make_hello(
        *loop, source->describe(), source_kind_name(spec.kind), device_offsets_or_null()));
    initial_params = loop->params();
    wanted_role = loop->role();
  }

  ServerCallbacks make_callbacks() {
    ServerCallbacks c;
    c.hello = [this] {
      ++summary.clients_seen;
      return hello;
    };
    c.on_text = [this](ClientId id, std::string_view text) { on_text(id, text); };
    c.on_rejected = [this](ClientId id, std::string_view reason) { reject(id, reason); };
    return c;
  }

  void log(const std::string& line) { options.log(line); }

  // ---- Start and stop ----

  Status start() {
    if (Status s = server.start(); !s) return s;
    if (!options.record_dir.empty()) {
      record_stem = options.record_stem.empty() ? start_stamp() : options.record_stem;
      if (Status s = start_recording(record_stem); !s) return s;
    }
    auto on_input = [this] { drain(); };
    auto log_fn = [this](const std::string& line) { log(line); };
    if (spec.kind == SourceKind::kNeuronTcp) {
      receiver = NeuronReceiver::connect_tcp(io, spec.host, spec.port, *neuron, on_input, log_fn);
    } else if (spec.kind == SourceKind::kNeuronUdp) {
      auto r = NeuronReceiver::bind_udp(io, spec.host, spec.port, *neuron, on_input, log_fn);
      if (!r) return r.error();
      receiver = std::move(r).value();
    } else if (spec.kind == SourceKind::kVmc) {
      if (vmc == nullptr) return Error{"a vmc source spec needs a VMC source"};
      auto r = VmcReceiver::bind(io, spec.host, spec.port, *vmc, on_input, log_fn);
      if (!r) return r.error();
      vmc_receiver = std::move(r).value();
    }
    if (!options.osc_host.empty()) {
      auto o = OscOutput::open(io, options.osc_host, options.osc_port);
      if (!o) return o.error();
      osc = std::move(o).value();
      log("OSC out to " + osc->where());
    }
    if (options.handle_signals) {
      signals.emplace(io, SIGINT, SIGTERM);
      signals->async_wait([this](error_code ec, int signal) {
        if (ec) return;
        log(fmt::format("{}: stopping", signal == SIGINT ? "SIGINT" : "SIGTERM"));
        shutdown();
      });
    }
    return Ok{};
  }

  // Opens a set of recording files for `role_loop`'s partner. Thread-safe (it only reads the
  // source's skeleton, which never changes), so the other role's set opens off the loop thread.
  static Result<std::unique_ptr<SessionRecorder>> open_recording(const std::string& directory,
                                                                 const std::string& stem,
                                                                 const SourceSkeleton& user,
                                                                 const LiveLoop& role_loop) {
    RecorderOptions r;
    r.directory = directory;
    r.stem = stem;
    // In the units duet assumes for each skeleton's convention, so that any duet command reads
    // the recordings back at the size they were danced (a WebSocket source sends metres).
    r.user_metres_per_unit = default_metres_per_unit(user.roles.convention);
    r.partner_metres_per_unit =
        default_metres_per_unit(role_loop.library().takes()[0].response_motion.roles.convention);
    return SessionRecorder::start(r, user.skeleton, role_loop.partner_skeleton(), user.frame_rate);
  }

  Status start_recording(const std::string& stem) {
    Result<std::unique_ptr<SessionRecorder>> started =
        open_recording(options.record_dir, stem, source->source_skeleton(), *loop);
    if (!started) return started.error();
    recorder = std::move(started).value();
    log_recording(*recorder);
    return Ok{};
  }

  void log_recording(const SessionRecorder& r) {
    log("recording to " + r.user_path() + ", " + r.partner_path() + ", " + r.follow_path());
  }

  // Completes a recording and adds it to the summary (all of its segments count).
  Status finish_recording(std::unique_ptr<SessionRecorder>& r) {
    if (!r) return Ok{};
    Status status = r->stop();
    summary.recordings.push_back(r->user_path());
    summary.recordings.push_back(r->partner_path());
    summary.recordings.push_back(r->follow_path());
    summary.recorded += r->frames_recorded();
    summary.record_lost += r->frames_lost();
    r.reset();
    return status;
  }

  Status run() {
    if (options.realtime) log("loop thread: " + raise_thread_priority());
    const auto now = SteadyClock::now();
    source->start(now);
    last_stats = last_log = now;
    schedule_replay();
    schedule_stats();
    io.run();
    if (options.realtime) use_normal_priority();

    // Stopped: the loop thread is this one, so no frame is in flight any more.
    if (receiver) receiver->stop();
    if (vmc_receiver) vmc_receiver->stop();
    server.stop();
    if (loader.joinable()) loader.join();
    // A model (and its recording) that finished loading after the stop is still in the queue.
    io.restart();
    io.poll();
    Status status = finish_recording(recorder);
    if (Status other = finish_recording(other_recorder); status && !other) status = other;
    finish_summary();
    return status;
  }

  void shutdown() {
    if (stopping) return;
    stopping = true;
    replay_timer.cancel();
    stats_timer.cancel();
    role_timer.cancel();
    if (signals) signals->cancel();
    if (receiver) receiver->stop();
    if (vmc_receiver) vmc_receiver->stop();
    server.stop();  // close frames to the WebSocket clients
    wait_for_close(SteadyClock::now() + kCloseGrace);
  }

  // Runs the io_context until every connection has closed (the close handshakes are done) or
  // the deadline has passed; a client that does not answer cannot hold the shutdown up.
  void wait_for_close(SteadyClock::time_point deadline) {
    if (server.connection_count() == 0 || SteadyClock::now() >= deadline) {
      io.stop();
      return;
    }
    shutdown_timer.expires_after(std::chrono::milliseconds(10));
    shutdown_timer.async_wait([this, deadline](error_code) { wait_for_close(deadline); });
  }

  void finish_summary() {
    summary.frames = frames;
    summary.rejected = rejected;
    summary.dropped = server.frames_dropped();
    LatencyHistogram send = send_total;
    send.merge(server.send_latency());
    LatencyHistogram built = loop_total;
    built.merge(loop_window);
    summary.latency_total = summarize(send);
    summary.loop_total = summarize(built);
    if (osc) {
      summary.osc_sent = osc->sent();
      summary.osc_dropped = osc->dropped();
    }
  }

  // ---- Frames ----

  void schedule_replay() {
    if (stopping) return;
    const std::optional<SteadyClock::time_point> due = source->next_due();
    if (!due) return;
    replay_timer.expires_at(*due);
    replay_timer.async_wait([this](error_code ec) {
      if (!ec && !stopping) drain();
    });
  }

  void drain() {
    if (stopping) return;
    const auto now = SteadyClock::now();
    while (source->poll(now, frame)) process(frame);
    if (source->next_due()) {
      schedule_replay();
    } else if (source->finished() && !source_end_reported) {
      source_end_reported = true;
      log(fmt::format("the source finished after {} frames{}", source->stats().frames,
                      options.exit_at_end ? "; stopping" : ""));
      if (options.exit_at_end) shutdown();
    }
  }

  void process(const SourceFrame& input) {
    const LiveOutput& out = loop->step(input);
    const std::int64_t step_us = microseconds(SteadyClock::now() - input.arrival);
    note_calibration_advice(out);
    if (recorder) recorder->push(input, out);
    std::shared_ptr<std::string> text = pool.acquire();
    format_frame(out, loop->params(), step_us, *text, frames);  // seq: since the start
    loop_window.record(microseconds(SteadyClock::now() - input.arrival));
    server.broadcast_frame(std::move(text), input.arrival);
    if (osc) osc->send(out, *loop, frames);
    ++frames;
  }

  // ---- Client messages ----

  void reject(ClientId id, std::string_view reason) {
    ++rejected;
    server.send(id, std::make_shared<const std::string>(make_error(reason)));
  }

  void on_text(ClientId id, std::string_view text) {
    if (std::optional<std::string> problem = parse_client_message(text, message)) {
      reject(id, *problem);
      return;
    }
    // With a control token (a server reachable from the network), a client that connected
    // without it can watch but not steer: every message changes the session for everyone.
    if (!server.may_control(id)) {
      reject(id,
             "this connection may only watch: open the address duet serve printed (with its "
             "?token=...) to send messages");
      return;
    }
    switch (message.type) {
      case ClientMessage::Type::kSet:
        loop->set_correction(message.correction, message.enabled);
        return;
      case ClientMessage::Type::kReset:
        // The follower starts over and the corrections go back to how the server started.
        loop->set_params(initial_params);
        loop->reset();
        forget_calibration_advice();
        return;
      case ClientMessage::Type::kRole:
        request_role(message.role);
        return;
      case ClientMessage::Type::kPose:
        if (pose == nullptr) {
          reject(id, "pose messages are for the WebSocket source (duet serve --source ws)");
          return;
        }
        if (!pose->push(message.time_s, message.root, message.rotations, SteadyClock::now(),
                        pose_reason)) {
          reject(id, pose_reason);
          return;
        }
        drain();
        return;
      case ClientMessage::Type::kXrPose:
        if (pose == nullptr) {
          reject(id, "xr_pose messages are for the headset source (duet serve --source xr)");
          return;
        }
        if (!pose->push_points(message.time_s, message.point_positions,
                               message.point_orientations, SteadyClock::now(), pose_reason)) {
          reject(id, pose_reason);
          return;
        }
        drain();
        return;
      case ClientMessage::Type::kReplay:
        control_replay(id);
        return;
      case ClientMessage::Type::kHeadHeight:
        set_head_height(id);
        return;
      case ClientMessage::Type::kArmsForward:
        set_arms_forward(id);
        return;
    }
  }

  // A height calibration from the headset (the viewer: both grips held while standing straight):
  // the eyes' offset taken off as from every pose. Kept across a role switch.
  void set_head_height(ClientId id) {
    const DevicePointOffsets* offsets = device_offsets_or_null();
    if (offsets == nullptr) {
      reject(id, "head_height messages are for the headset source (duet serve --source xr)");
      return;
    }
    if (Status s = loop->set_head_height(head_joint_height_m(message.head_height_m, *offsets));
        !s) {
      reject(id, "head_height: " + s.error().message);
      return;
    }
    log(message.head_height_m > 0.0
            ? fmt::format("the headset's height standing: {:.2f} m (the user's size from it)",
                          message.head_height_m)
            : std::string("the user's size is learnt again from the highest the head has held"));
  }

  // A body calibration from the headset (the viewer: both grips held while standing straight with
  // both arms held straight forward): where the latest pose holds the wrists (joints, the device
  // offsets taken out), in the calibrated head height or else the head's height now. Kept across
  // a role switch.
  void set_arms_forward(ClientId id) {
    if (device_offsets_or_null() == nullptr) {
      reject(id, "arms_forward messages are for the headset source (duet serve --source xr)");
      return;
    }
    if (message.forget_arms_forward) {
      (void)loop->set_arms_forward(std::nullopt);
      forget_calibration_advice();
      log("the body calibration is forgotten: the hands are taken as they come");
      return;
    }
    if (frames == 0) {
      reject(id, "arms_forward: no pose from the headset yet (send xr_pose first)");
      return;
    }
    // Two frames of the one pose: what a three-point CSV holds at least, should it be recorded.
    Clip latest(source->source_skeleton().skeleton, source->source_skeleton().frame_rate, 2);
    for (int f = 0; f < latest.frame_count(); ++f) {
      std::ranges::copy(frame.translations_ls, latest.translations_ls(f).begin());
      std::ranges::copy(frame.rotations_ls, latest.rotations_ls(f).begin());
    }
    Result<ArmsForward> arms = arms_forward_of_points(latest, loop->head_height_m());
    if (!arms) {
      reject(id, arms.error().message);
      return;
    }
    if (Status s = loop->set_arms_forward(arms.value()); !s) {
      reject(id, s.error().message);
      return;
    }
    forget_calibration_advice();
    const ArmsForward& held = arms.value();
    log(fmt::format(
        "arms held forward: the wrists {:.2f} head heights apart, {:.2f} in front of "
        "the head (the body's calibration)",
        held.wrists[0].x() - held.wrists[1].x(), 0.5 * (held.wrists[0].z() + held.wrists[1].z())));
    if (recorder) record_calibration(latest);
  }

  // The calibration pose beside the recording ("<stem>-calibration.csv", a three-point CSV at the
  // joints, the latest one of the session), so that `duet follow --input <stem>-user.bvh
  // --calibration <stem>-calibration.csv` follows the recording as it was followed live.
  void record_calibration(const Clip& held_pose) {
    std::string path = recorder->user_path();
    constexpr std::string_view kUserSuffix = "-user.bvh";
    if (!path.ends_with(kUserSuffix)) return;
    path.replace(path.size() - kUserSuffix.size(), kUserSuffix.size(), "-calibration.csv");
    if (Status s = write_file_atomically(path, format_points_csv(held_pose)); !s) {
      log("the calibration pose was not recorded: " + s.error().message);
      return;
    }
    log("the calibration pose is recorded in " + path);
  }

  // Pause, seek, speed of a file replay; every client sees the new state.
  void control_replay(ClientId id) {
    if (replay == nullptr) {
      reject(id, "replay messages need a file replay (duet serve --source replay:FILE)");
      return;
    }
    const auto now = SteadyClock::now();
    if (message.replay_speed) replay->set_speed(*message.replay_speed, now);
    if (message.replay_seek_s) replay->seek(*message.replay_seek_s, now);
    if (message.replay_paused) replay->set_paused(*message.replay_paused, now);
    source_end_reported = false;  // a seek may bring a finished replay back
    drain();                      // a seek while paused delivers its frame now
    broadcast_replay_state();
  }

  void broadcast_replay_state() {
    if (replay)
      server.broadcast(std::make_shared<const std::string>(make_replay_state(replay->state())));
  }

  // ---- Role switching ----
  //
  // The other role's model is built once, on a background thread (with its set of recording
  // files), and kept: later switches only swap the two (no thread, no file work, no message
  // built on the loop's thread). Switches are applied at most every kRoleInterval; requests in
  // between are coalesced into the last one, so a client toggling the role as fast as it can
  // costs the loop a few swaps per second and never splits the recording further.

  void request_role(DancerRole role) {
    wanted_role = role;
    if (role_timer_armed) return;  // the pending switch will apply the latest wish
    const auto due = last_switch + kRoleInterval;
    if (SteadyClock::now() < due) {
      role_timer_armed = true;
      role_timer.expires_at(due);
      role_timer.async_wait([this](error_code ec) {
        role_timer_armed = false;
        if (!ec && !stopping) apply_role();
      });
      return;
    }
    apply_role();
  }

  void apply_role() {
    if (stopping) return;
    const DancerRole role = wanted_role;
    if (role == loop->role()) return;  // a load in progress for the other role is kept for later
    if (other_loop && other_loop->role() == role) {
      activate_other();
      return;
    }
    if (loading) return;
    loading = true;
    log(fmt::format("building the model for the {} role", dancer_role_name(role)));
    if (loader.joinable()) loader.join();  // finished: on_loaded has run
    std::string stem =
        recorder ? fmt::format("{}-seg2", record_stem) : std::string();  // empty: no recording
    loader = std::thread([this, role, params = loop->params(), user = source->source_skeleton(),
                          directory = options.record_dir, stem = std::move(stem)] {
      use_normal_priority();  // building a model takes seconds of CPU: never at the loop's priority
      auto loaded = std::make_shared<Loaded>();
      loaded->loop = Error{"no factory"};
      if (factory) {
        try {
          loaded->loop = factory(role, params);
        } catch (const std::exception& e) {
          loaded->loop = Error{e.what()};
        }
      }
      if (loaded->loop) {
        loaded->hello = std::make_shared<const std::string>(
            make_hello(*loaded->loop.value(), source_description, source_kind_name(spec.kind),
                       device_offsets_or_null()));
        if (!stem.empty()) {
          Result<std::unique_ptr<SessionRecorder>> r =
              open_recording(directory, stem, user, *loaded->loop.value());
          if (r) {
            loaded->recorder = std::move(r).value();
          } else {
            loaded->record_error = r.error().message;
          }
        }
      }
      asio::post(io, [this, role, loaded] { on_loaded(role, std::move(*loaded)); });
    });
  }

  struct Loaded {
    Result<std::unique_ptr<LiveLoop>> loop = Error{""};
    std::shared_ptr<const std::string> hello;
    std::unique_ptr<SessionRecorder> recorder;
    std::string record_error;
  };

  void on_loaded(DancerRole role, Loaded loaded) {
    loading = false;
    if (loaded.recorder) {
      log_recording(*loaded.recorder);
      other_recorder = std::move(loaded.recorder);
    } else if (!loaded.record_error.empty()) {
      log("the " + std::string(dancer_role_name(role)) +
          " role will not be recorded: " + loaded.record_error);
    }
    if (stopping) return;
    if (!loaded.loop) {
      const std::string why = fmt::format("cannot switch to the {} role: {}",
                                          dancer_role_name(role), loaded.loop.error().message);
      log(why);
      server.broadcast(std::make_shared<const std::string>(make_error(why)));
      if (wanted_role == role) wanted_role = loop->role();
      return;
    }
    other_loop = std::move(loaded.loop).value();
    other_hello = std::move(loaded.hello);
    if (wanted_role == role) activate_other();
  }

  void activate_other() {
    other_loop->set_params(loop->params());
    // In range: this loop took it.
    (void)other_loop->set_head_height(loop->head_height_m());
    (void)other_loop->set_arms_forward(loop->arms_forward());
    other_loop->reset();
    forget_calibration_advice();
    std::swap(loop, other_loop);
    std::swap(hello, other_hello);
    std::swap(recorder, other_recorder);
    last_switch = SteadyClock::now();
    server.broadcast(hello);
    log(fmt::format("the user now dances the {}", dancer_role_name(loop->role())));
  }

  // ---- Whether three points need a body calibration (calibration_advice.h) ----

  // Counts the frame's learnt offset while the user is three points without a body calibration.
  void note_calibration_advice(const LiveOutput& out) {
    const bool counts = three_point_source && !loop->arms_forward() && advice_time_s;
    if (counts) calibration_advice.observe(out.follow, out.time_s - *advice_time_s);
    advice_time_s = out.time_s;
  }

  void forget_calibration_advice() {
    calibration_advice.reset();
    advice_time_s.reset();
    calibration_advised = false;
  }

  // The learnt offset while it is another body's (for `stats`), logged the first time.
  std::optional<float> calibration_advice_now() {
    const std::optional<float> offset = calibration_advice.other_body_offset();
    if (offset && !calibration_advised) {
      calibration_advised = true;
      log(fmt::format(
          "the hands are held elsewhere against the head than the library's dancers hold them (a "
          "learnt offset of {:.3f}; the library's own body under 0.02): until the follower has "
          "learnt it, it places the user less surely. A body calibration gives it at once: {}",
          *offset,
          device_offsets_or_null() != nullptr
              ? "in the viewer, stand straight with both arms held straight forward and hold both "
                "grips for a second"
              : "duet serve --calibration POSE.csv (a second of the user standing straight with "
                "both arms held straight forward)"));
    }
    return offset;
  }

  // ---- Statistics ----

  void schedule_stats() {
    stats_timer.expires_after(std::chrono::duration_cast<SteadyClock::duration>(
        std::chrono::duration<double>(options.stats_interval_s)));
    stats_timer.async_wait([this](error_code ec) {
      if (ec || stopping) return;
      stats_tick();
      schedule_stats();
    });
  }

  void stats_tick() {
    server.close_stalled_clients();
    const auto now = SteadyClock::now();
    LatencyHistogram& send = server.send_latency();
    send_total.merge(send);
    send_log.merge(send);
    loop_total.merge(loop_window);
    loop_log.merge(loop_window);

    StatsSnapshot s;
    s.frames = frames;
    s.clients = server.client_count();
    s.dropped = server.frames_dropped();
    s.rejected = rejected;
    const double window_s = std::chrono::duration<double>(now - last_stats).count();
    s.rate_hz = window_s > 0.0 ? static_cast<double>(frames - frames_at_stats) / window_s : 0.0;
    s.latency = summarize(send);
    s.latency_total = summarize(send_total);
    s.loop = summarize(loop_window);
    s.source = source->stats();
    for (const auto* r : {&recorder, &other_recorder}) {  // both roles' files
      if (*r) {
        s.recorded += (*r)->frames_recorded();
        s.record_lost += (*r)->frames_lost();
      }
    }
    s.calibration_offset = calibration_advice_now();
    server.broadcast(std::make_shared<const std::string>(make_stats(s)));
    broadcast_replay_state();  // clients that connected since the last change learn it here
    send.clear();
    loop_window.clear();
    last_stats = now;
    frames_at_stats = frames;

    const double log_s = std::chrono::duration<double>(now - last_log).count();
    if (options.log_interval_s > 0.0 && log_s >= options.log_interval_s - 1e-3) {
      const LatencySummary sent = summarize(send_log);
      const LatencySummary built = summarize(loop_log);
      log(fmt::format(
          "{} frames in {:.1f} s ({:.1f} Hz), {} client(s); arrival->sent p50 {} ms, p99 {} ms, "
          "max {} ms; arrival->built p50 {} ms, p99 {} ms; dropped {}, rejected {}, source "
          "rejected {}",
          frames - frames_at_log, log_s, static_cast<double>(frames - frames_at_log) / log_s,
          s.clients, ms(sent.p50), ms(sent.p99), ms(sent.max), ms(built.p50), ms(built.p99),
          s.dropped, s.rejected, s.source.rejected));
      send_log.clear();
      loop_log.clear();
      last_log = now;
      frames_at_log = frames;
    }
  }

  LiveServerOptions options;
  SourceSpec spec;
  std::unique_ptr<FrameSource> source;
  NeuronSource* neuron = nullptr;
  PoseSource* pose = nullptr;
  ReplaySource* replay = nullptr;
  std::unique_ptr<LiveLoop> loop;
  LoopFactory factory;

  asio::io_context io;
  Server server;
  asio::steady_timer replay_timer;
  asio::steady_timer stats_timer;
  asio::steady_timer role_timer;
  asio::steady_timer shutdown_timer;
  std::optional<asio::signal_set> signals;
  std::unique_ptr<NeuronReceiver> receiver;
  VmcSource* vmc = nullptr;
  std::unique_ptr<VmcReceiver> vmc_receiver;
  std::unique_ptr<OscOutput> osc;
  bool stopping = false;

  // The active role's recording and the other role's (opened with its model).
  std::unique_ptr<SessionRecorder> recorder, other_recorder;
  std::string record_stem;

  SourceFrame frame;
  MessagePool pool;
  std::shared_ptr<const std::string> hello;
  ClientMessage message;
  std::string pose_reason;

  std::unique_ptr<LiveLoop> other_loop;
  std::shared_ptr<const std::string> other_hello;
  std::string source_description = source->describe();
  // The user is three points (a headset, or a three-point replay): CalibrationAdvice applies.
  const bool three_point_source = is_head_hands_input(source->source_skeleton().roles);
  // What the headset source takes out of each xr_pose (for hello); null for other sources.
  const DevicePointOffsets* device_offsets_or_null() const {
    return pose && spec.kind == SourceKind::kXr ? &pose->device_offsets() : nullptr;
  }
  std::thread loader;
  bool loading = false;
  DancerRole wanted_role = DancerRole::kLeader;
  PartnerParams initial_params;  // what `reset` restores
  static constexpr auto kRoleInterval = std::chrono::milliseconds(250);
  static constexpr auto kCloseGrace = std::chrono::milliseconds(1000);
  SteadyClock::time_point last_switch{};
  bool role_timer_armed = false;

  long long frames = 0;
  long long rejected = 0;
  bool source_end_reported = false;
  CalibrationAdvice calibration_advice;
  std::optional<double> advice_time_s;  // the previous frame's time, for the advice's durations
  bool calibration_advised = false;     // logged once until it is forgotten
  LatencyHistogram loop_window, loop_log, loop_total;
  LatencyHistogram send_log, send_total;
  SteadyClock::time_point last_stats{}, last_log{};
  long long frames_at_stats = 0, frames_at_log = 0;
  ServeSummary summary;
};

LiveServer::LiveServer(LiveServerOptions options, SourceSpec spec,
                       std::unique_ptr<FrameSource> source, std::unique_ptr<LiveLoop> loop,
                       LoopFactory factory)
    : impl_(std::make_unique<Impl>(std::move(options), std::move(spec), std::move(source),
                                   std::move(loop), std::move(factory))) {}

LiveServer::~LiveServer() {
  if (impl_->loader.joinable()) impl_->loader.join();
}

Status LiveServer::start() { return impl_->start(); }
std::uint16_t LiveServer::port() const { return impl_->server.port(); }
const std::filesystem::path* LiveServer::web_root() const { return impl_->server.web_root(); }
Status LiveServer::run() { return impl_->run(); }
void LiveServer::stop() {
  Impl* impl = impl_.get();
  asio::post(impl->io, [impl] { impl->shutdown(); });
}
const ServeSummary& LiveServer::summary() const { return impl_->summary; }

}  // namespace duet::net
