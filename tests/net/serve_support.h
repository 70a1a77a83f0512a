// Helpers for the `duet serve` integration tests: start the real binary (DUET_BINARY) on a free
// port, talk to it over loopback with Beast clients that never block without a deadline.
#pragma once

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace duet::test {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace fs = std::filesystem;
using tcp = asio::ip::tcp;
using Json = nlohmann::json;
using namespace std::chrono_literals;

inline std::string salsa(const std::string& subject, const std::string& trial) {
  return std::string(DUET_DATA_DIR) + "/cmu-salsa/bvh/" + subject + "/" + subject + "_" + trial +
         "_scaled.bvh";
}

struct TempDir {
  fs::path path;
  explicit TempDir(const std::string& name) {
    path = fs::temp_directory_path() / (name + "-" + std::to_string(::getpid()));
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
};

inline std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The `duet serve` process: started with --http 127.0.0.1:0, its port read from the stdout line.
class ServeProcess {
 public:
  ServeProcess() = default;
  ServeProcess(const ServeProcess&) = delete;
  ServeProcess& operator=(const ServeProcess&) = delete;
  ~ServeProcess() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      int status = 0;
      ::waitpid(pid_, &status, 0);
    }
    if (stdout_fd_ >= 0) ::close(stdout_fd_);
  }

  // Starts `duet serve ARGS --http 127.0.0.1:0` (or `http`); stderr goes to `log_path`. Waits for
  // the address line; false if the process exits first (see wait_exit()).
  bool start(std::vector<std::string> args, const fs::path& log_path,
             std::chrono::milliseconds timeout = 60s, const std::string& http = "127.0.0.1:0") {
    log_path_ = log_path;
    args.insert(args.begin(), {DUET_BINARY, "serve"});
    args.insert(args.end(), {"--http", http});
    int out[2];
    if (::pipe(out) != 0) return false;
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, out[1], 1);
    posix_spawn_file_actions_addclose(&actions, out[0]);
    posix_spawn_file_actions_addopen(&actions, 2, log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    const int rc = ::posix_spawn(&pid_, DUET_BINARY, &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(out[1]);
    stdout_fd_ = out[0];
    if (rc != 0) {
      pid_ = -1;
      return false;
    }
    // Read stdout until "viewer at http://127.0.0.1:PORT/".
    std::string text;
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      pollfd p{stdout_fd_, POLLIN, 0};
      if (::poll(&p, 1, 100) <= 0) continue;
      char buffer[512];
      const ssize_t n = ::read(stdout_fd_, buffer, sizeof buffer);
      if (n <= 0) return false;  // exited
      text.append(buffer, static_cast<std::size_t>(n));
      const std::size_t at = text.find("http://127.0.0.1:");
      if (at != std::string::npos && text.find('\n', at) != std::string::npos) {
        port_ = static_cast<std::uint16_t>(std::stoi(text.substr(at + 17)));
        address_line_ = text.substr(at, text.find('\n', at) - at);
        return true;
      }
    }
    return false;
  }

  std::uint16_t port() const { return port_; }
  pid_t pid() const { return pid_; }
  // From "http://..." to the end of the address line.
  const std::string& address_line() const { return address_line_; }

  // Waits for the process to exit by itself; its exit status (-1 on timeout or a crash).
  int wait_exit(std::chrono::milliseconds timeout = 60s) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    int status = 0;
    while (pid_ > 0 && std::chrono::steady_clock::now() < deadline) {
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      }
      std::this_thread::sleep_for(10ms);
    }
    return -1;
  }
  std::string log() const { return read_text(log_path_); }

  // Sends `signal` and waits for the exit; returns the exit status (-1 on timeout or a crash).
  int stop(int signal = SIGTERM, std::chrono::milliseconds timeout = 20s) {
    if (pid_ <= 0) return -1;
    ::kill(pid_, signal);
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    int status = 0;
    while (std::chrono::steady_clock::now() < deadline) {
      const pid_t r = ::waitpid(pid_, &status, WNOHANG);
      if (r == pid_) {
        pid_ = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      }
      std::this_thread::sleep_for(10ms);
    }
    return -1;
  }

  bool running() const {
    if (pid_ <= 0) return false;
    int status = 0;
    return ::waitpid(pid_, &status, WNOHANG) == 0;
  }

 private:
  pid_t pid_ = -1;
  int stdout_fd_ = -1;
  std::uint16_t port_ = 0;
  std::string address_line_;
  fs::path log_path_;
};

// A WebSocket client whose every operation has a deadline (a hung server fails the test instead
// of hanging it).
class WsClient {
 public:
  // `from`: the local address to connect from (another loopback address such as 127.0.0.2
  // looks like another machine to the server's per-address limits).
  bool connect(std::uint16_t port, const std::string& target = "/ws",
               const std::string& from = "") {
    beast::error_code result = asio::error::would_block;
    auto& layer = beast::get_lowest_layer(ws_);
    if (!from.empty()) {
      beast::error_code ec;
      layer.socket().open(tcp::v4(), ec);
      if (!ec) layer.socket().bind(tcp::endpoint(asio::ip::make_address(from), 0), ec);
      if (ec) return false;
    }
    layer.expires_after(5s);
    layer.async_connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port),
                        [&](beast::error_code ec) { result = ec; });
    run();
    if (result) return false;
    result = asio::error::would_block;
    ws_.async_handshake("127.0.0.1:" + std::to_string(port), target,
                        [&](beast::error_code ec) { result = ec; });
    run();
    layer.expires_never();
    return !result;
  }

  // The next message, or nullopt after `timeout` (the connection is then closed).
  std::optional<std::string> read_text(std::chrono::milliseconds timeout = 5s) {
    beast::error_code result = asio::error::would_block;
    buffer_.clear();
    ws_.async_read(buffer_, [&](beast::error_code ec, std::size_t) { result = ec; });
    io_.restart();
    io_.run_for(timeout);
    if (result == asio::error::would_block) {
      beast::get_lowest_layer(ws_).close();
      run();
      return std::nullopt;
    }
    if (result) return std::nullopt;
    return beast::buffers_to_string(buffer_.data());
  }

  std::optional<Json> read_json(std::chrono::milliseconds timeout = 5s) {
    std::optional<std::string> text = read_text(timeout);
    if (!text) return std::nullopt;
    Json j = Json::parse(*text, nullptr, false);
    if (j.is_discarded()) return std::nullopt;
    return j;
  }

  // The next message of `type` (others are skipped), or nullopt.
  // The default wait is generous: a working server answers in milliseconds, but a sanitizer
  // build on a loaded 2-core machine was seen to take over 5 s to turn a message around.
  std::optional<Json> read_type(const std::string& type, std::chrono::milliseconds timeout = 20s) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline - std::chrono::steady_clock::now());
      std::optional<Json> j = read_json(std::max(left, 1ms));
      if (!j) return std::nullopt;
      if ((*j)["type"] == type) return j;
    }
    return std::nullopt;
  }

  bool write(const std::string& text, bool binary = false) {
    beast::error_code ec;
    ws_.binary(binary);
    ws_.write(asio::buffer(text), ec);
    return !ec;
  }

  // The first part of a message (fin = false): the rest never comes.
  bool write_partial(const std::string& text) {
    beast::error_code ec;
    ws_.text(true);
    ws_.write_some(false, asio::buffer(text), ec);
    return !ec;
  }

  void drop() { beast::get_lowest_layer(ws_).close(); }

  websocket::stream<beast::tcp_stream>& stream() { return ws_; }
  asio::io_context& io() { return io_; }

 private:
  void run() {
    io_.restart();
    io_.run();
  }

  asio::io_context io_;
  websocket::stream<beast::tcp_stream> ws_{io_};
  beast::flat_buffer buffer_;
};

struct HttpReply {
  int status = 0;
  std::string content_type;
  std::string body;
  std::size_t content_length = 0;
};

// One HTTP request with a raw target (not normalised, so "/../x" reaches the server as is).
inline std::optional<HttpReply> http_request(std::uint16_t port, http::verb verb,
                                             const std::string& target) {
  asio::io_context io;
  beast::tcp_stream stream(io);
  stream.expires_after(5s);
  beast::error_code ec;
  stream.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port), ec);
  if (ec) return std::nullopt;
  http::request<http::empty_body> request{verb, target, 11};
  request.set(http::field::host, "127.0.0.1");
  request.keep_alive(false);
  http::response_parser<http::string_body> parser;
  parser.skip(verb == http::verb::head);
  beast::flat_buffer buffer;
  beast::error_code result = asio::error::would_block;
  http::async_write(stream, request, [&](beast::error_code write_ec, std::size_t) {
    if (write_ec) {
      result = write_ec;
      return;
    }
    http::async_read(stream, buffer, parser,
                     [&](beast::error_code read_ec, std::size_t) { result = read_ec; });
  });
  io.run();
  if (result) return std::nullopt;
  HttpReply reply;
  reply.status = static_cast<int>(parser.get().result_int());
  reply.content_type = std::string(parser.get()[http::field::content_type]);
  reply.body = parser.get().body();
  if (parser.content_length())
    reply.content_length = static_cast<std::size_t>(*parser.content_length());
  return reply;
}

}  // namespace duet::test
