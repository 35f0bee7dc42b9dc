// Helpers of the live-mode loopback test and benchmark: recorded streams cut into epochs
// (a rover UBX log at its RXM-RAWX frames, an RTCM 3 log where the decoder closes an
// observation epoch), child processes (str2str, gvins-rtk) and free local ports.
#pragma once

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "gvins/rtcm/decoder.hpp"
#include "gvins/ubx/stream_splitter.hpp"

namespace gvins::livetest {

inline std::vector<std::uint8_t> readBytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

/// The log cut after each RXM-RAWX frame (what precedes a RAWX goes with it).
inline std::vector<std::vector<std::uint8_t>> ubxEpochs(const std::vector<std::uint8_t>& log) {
  ubx::StreamSplitter sp;
  sp.feed(log);
  sp.finish();
  ubx::StreamFrame f;
  std::vector<std::vector<std::uint8_t>> out;
  std::size_t from = 0;
  while (sp.next(f)) {
    if (f.kind == ubx::StreamKind::Ubx && f.ubx().type() == 0x0215) {
      const std::size_t end = static_cast<std::size_t>(f.offset) + f.bytes.size();
      out.emplace_back(log.begin() + static_cast<std::ptrdiff_t>(from), log.begin() + static_cast<std::ptrdiff_t>(end));
      from = end;
    }
  }
  return out;
}

/// The log cut after each frame that completes an observation epoch.
inline std::vector<std::vector<std::uint8_t>> rtcmEpochs(const std::vector<std::uint8_t>& log) {
  rtcm::Decoder d;
  std::vector<std::vector<std::uint8_t>> out;
  std::size_t from = 0;
  std::size_t i = 0;
  while (i + 3 <= log.size()) {
    // Frame by frame: 0xD3, 6 reserved bits, 10-bit length, message, 3 CRC bytes.
    const std::size_t len = ((log[i + 1] & 0x03u) << 8 | log[i + 2]) + 6;
    if (log[i] != 0xD3 || i + len > log.size()) break;
    d.feed({log.data() + i, len});
    i += len;
    while (auto r = d.poll()) {
      if (std::holds_alternative<ObsEpoch>(*r)) {
        out.emplace_back(log.begin() + static_cast<std::ptrdiff_t>(from), log.begin() + static_cast<std::ptrdiff_t>(i));
        from = i;
      }
    }
  }
  return out;
}

inline int freePort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
  socklen_t len = sizeof a;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  ::close(fd);
  return ntohs(a.sin_port);
}

/// Everything a TCP client of 127.0.0.1:`port` receives until the server closes (in a thread).
class TcpCollector {
 public:
  explicit TcpCollector(int port) {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = htons(static_cast<std::uint16_t>(port));
    connected_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
    if (connected_) {
      thread_ = std::thread([this] {
        char buf[4096];
        for (ssize_t n; (n = ::recv(fd_, buf, sizeof buf, 0)) > 0;) text_.append(buf, static_cast<std::size_t>(n));
      });
    }
  }
  ~TcpCollector() { finish(); }
  bool connected() const { return connected_; }
  /// Waits for the server to close the connection; the bytes received.
  const std::string& finish() {
    if (thread_.joinable()) thread_.join();
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    return text_;
  }

 private:
  int fd_ = -1;
  bool connected_ = false;
  std::thread thread_;
  std::string text_;
};

/// A child process with its standard input from a pipe (`writer`) and its standard error (and,
/// unless `stdoutFile`, output) to `errFile`.
class Child {
 public:
  Child(std::vector<std::string> argv, const std::string& errFile, bool pipeIn) {
    int p[2] = {-1, -1};
    if (pipeIn && ::pipe(p) != 0) return;
    pid_ = ::fork();
    if (pid_ == 0) {
      if (pipeIn) {
        ::dup2(p[0], 0);
        ::close(p[0]);
        ::close(p[1]);
      }
      const int e = ::open(errFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(e, 2);
      ::dup2(e, 1);
      std::vector<char*> a;
      for (auto& s : argv) a.push_back(s.data());
      a.push_back(nullptr);
      ::execvp(a[0], a.data());
      ::_exit(127);
    }
    if (pipeIn) {
      ::close(p[0]);
      in_ = p[1];
    }
  }
  ~Child() {
    closeInput();
    stop();
  }
  bool write(const std::vector<std::uint8_t>& d) {
    std::size_t sent = 0;
    while (sent < d.size()) {
      const ssize_t n = ::write(in_, d.data() + sent, d.size() - sent);
      if (n <= 0) return false;
      sent += static_cast<std::size_t>(n);
    }
    return true;
  }
  void closeInput() {
    if (in_ >= 0) ::close(in_);
    in_ = -1;
  }
  /// SIGTERM and wait; returns the exit status (-1 if not running).
  int stop() {
    if (pid_ <= 0) return -1;
    ::kill(pid_, SIGTERM);
    return wait();
  }
  int wait() {
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }
  pid_t pid() const { return pid_; }

 private:
  pid_t pid_ = -1;
  int in_ = -1;
};

inline std::string readText(const std::string& path) {
  std::ifstream f(path);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

}  // namespace gvins::livetest
