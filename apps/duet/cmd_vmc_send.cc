// duet vmc-send TAKE [--to HOST:PORT] [--speed S]: plays a take as a VMC performer would (XR
// Animator, VSeeFace, ...), so `duet serve --source vmc` can be tried without a VMC app. The take
// is retargeted onto the VMC humanoid (duet/live/vmc_humanoid.h) and each frame goes out at the
// take's rate as one OSC bundle: /VMC/Ext/Root/Pos, /VMC/Ext/Bone/Pos per bone (Unity axes),
// /VMC/Ext/OK, /VMC/Ext/T. docs/vmc.md.
#include <fmt/format.h>
#include <lo/lo.h>

#include <chrono>
#include <memory>
#include <thread>

#include "commands.h"
#include "duet/io/motion_argument.h"
#include "duet/io/motion_file.h"
#include "duet/live/vmc_humanoid.h"
#include "duet/motion/retarget.h"
#include "duet/net/osc_output.h"
#include "motion_options.h"
#include "number_checks.h"

namespace duet::app {

namespace {

struct VmcSendArgs {
  std::string input;
  MotionFileOptions motion;
  std::string to = "127.0.0.1:39539";
  double speed = 1.0;
  bool loop = false;
};

void fail(const std::string& message) { fmt::print(stderr, "duet vmc-send: {}\n", message); }

struct AddressDeleter {
  void operator()(void* a) const { lo_address_free(static_cast<lo_address>(a)); }
};
struct BundleDeleter {
  void operator()(void* b) const { lo_bundle_free_recursive(static_cast<lo_bundle>(b)); }
};

// One frame as a VMC bundle. liblo allocates per message: fine here, this is not the live loop.
lo_bundle make_bundle(const Skeleton& humanoid, std::span<const Vec3> translations,
                      std::span<const Quat> rotations, double time_s) {
  lo_bundle bundle = lo_bundle_new(LO_TT_IMMEDIATE);
  lo_message root = lo_message_new();
  lo_message_add_string(root, "root");
  for (const double v : {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0}) {
    lo_message_add_float(root, static_cast<float>(v));
  }
  lo_bundle_add_message(bundle, "/VMC/Ext/Root/Pos", root);
  for (int j = 0; j < humanoid.joint_count(); ++j) {
    const Joint& joint = humanoid.joints[static_cast<std::size_t>(j)];
    if (joint.end_site) continue;
    const Vec3 p = duet_to_unity(translations[static_cast<std::size_t>(j)]);
    const Quat q = duet_to_unity(rotations[static_cast<std::size_t>(j)]);
    lo_message m = lo_message_new();
    lo_message_add_string(m, joint.name.c_str());
    for (const double v : {p.x(), p.y(), p.z(), q.x(), q.y(), q.z(), q.w()}) {
      lo_message_add_float(m, static_cast<float>(v));
    }
    lo_bundle_add_message(bundle, "/VMC/Ext/Bone/Pos", m);
  }
  lo_message ok = lo_message_new();
  lo_message_add_int32(ok, 1);
  lo_bundle_add_message(bundle, "/VMC/Ext/OK", ok);
  lo_message t = lo_message_new();
  lo_message_add_float(t, static_cast<float>(time_s));
  lo_bundle_add_message(bundle, "/VMC/Ext/T", t);
  return bundle;
}

int run_vmc_send(const VmcSendArgs& args) {
  std::string host;
  std::uint16_t port = 0;
  if (!net::parse_osc_target(args.to, host, port)) {
    fail("--to '" + args.to + "': expected HOST:PORT (e.g. 127.0.0.1:39539)");
    return kExitUsage;
  }
  Result<std::vector<std::string>> files = split_motion_argument(args.input);
  if (!files) {
    fail(files.error().message);
    return kExitUsage;
  }
  MotionLoadOptions load_options;
  if (!make_load_options(args.motion, load_options)) return kExitFailure;
  Result<LoadedMotion> take = load_motion(files.value(), load_options);
  if (!take) {
    fail(take.error().message);
    return kExitFailure;
  }
  const Clip& in = take.value().clip;
  const SourceSkeleton humanoid = vmc_humanoid(in.frame_rate());
  Result<Retargeter> retargeter =
      Retargeter::create(in.skeleton_ptr(), take.value().roles, humanoid.skeleton, humanoid.roles,
                         {}, take.value().description, "the VMC humanoid");
  if (!retargeter) {
    fail(retargeter.error().message);
    return kExitFailure;
  }
  std::unique_ptr<void, AddressDeleter> address(
      lo_address_new(host.c_str(), std::to_string(port).c_str()));
  if (!address) {
    fail("--to " + args.to + ": cannot make an OSC address");
    return kExitFailure;
  }

  const int joints = humanoid.joint_count();
  std::vector<Vec3> translations(static_cast<std::size_t>(joints));
  std::vector<Quat> rotations(static_cast<std::size_t>(joints));
  const double frame_s = in.frame_time() / args.speed;
  fmt::print(stderr, "duet vmc-send: {} ({} frames at {:g} fps, x{:g}) to {} as VMC\n",
             take.value().description, in.frame_count(), in.frame_rate(), args.speed, args.to);
  long long sent = 0;
  const auto start = std::chrono::steady_clock::now();
  do {
    for (int f = 0; f < in.frame_count(); ++f, ++sent) {
      retargeter.value().retarget_frame(in.translations_ls(f), in.rotations_ls(f), translations,
                                        rotations);
      std::unique_ptr<void, BundleDeleter> bundle(make_bundle(
          *humanoid.skeleton, translations, rotations, static_cast<double>(sent) * frame_s));
      // On schedule from the start, so a late frame does not delay the ones after it.
      std::this_thread::sleep_until(
          start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                      std::chrono::duration<double>(static_cast<double>(sent) * frame_s)));
      if (lo_send_bundle(address.get(), bundle.get()) < 0) {
        fail(fmt::format("sending frame {} to {}: {}", f, args.to,
                         lo_address_errstr(address.get())));
        return kExitFailure;
      }
    }
  } while (args.loop);
  fmt::print(stderr, "duet vmc-send: sent {} frames\n", sent);
  return kExitOk;
}

}  // namespace

Command register_vmc_send(CLI::App& app) {
  auto args = std::make_shared<VmcSendArgs>();
  app.add_option("take", args->input, "The take to play: a BVH file, or SKELETON.asf+MOTION.amc")
      ->required();
  add_motion_file_options(app, args->motion);
  app.add_option("--to", args->to, "Where the VMC receiver listens (HOST:PORT)")
      ->capture_default_str();
  app.add_option("--speed", args->speed, "Playback speed (1: the take's rate)")
      ->check(number_between(0.05, 20.0))
      ->capture_default_str();
  app.add_flag("--loop", args->loop, "Play the take again and again (until interrupted)");
  return [args] { return run_vmc_send(*args); };
}

}  // namespace duet::app
