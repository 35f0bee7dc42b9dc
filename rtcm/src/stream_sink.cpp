#include "gvins/rtcm/stream_sink.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include "tcp_socket.hpp"

namespace gvins::rtcm {

namespace {

using Clock = std::chrono::steady_clock;
constexpr std::size_t kMaxBacklog = 1u << 20;  // bytes a receiver may fall behind before it is dropped
// Kernel send buffer of a receiver's socket: bounded (no autotuning to several MiB), so that how
// far a receiver is behind is seen, and limited, by the sink.
constexpr int kSendBuffer = 256 * 1024;

void boundSendBuffer(int fd) { ::setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &kSendBuffer, sizeof kSendBuffer); }

std::string peerName(int fd) {
  sockaddr_storage ss{};
  socklen_t len = sizeof ss;
  if (::getpeername(fd, reinterpret_cast<sockaddr*>(&ss), &len) != 0) return "?";
  char host[INET6_ADDRSTRLEN] = "?";
  int port = 0;
  if (ss.ss_family == AF_INET6) {
    const auto* a = reinterpret_cast<sockaddr_in6*>(&ss);
    ::inet_ntop(AF_INET6, &a->sin6_addr, host, sizeof host);
    port = ntohs(a->sin6_port);
  } else {
    const auto* a = reinterpret_cast<sockaddr_in*>(&ss);
    ::inet_ntop(AF_INET, &a->sin_addr, host, sizeof host);
    port = ntohs(a->sin_port);
  }
  return std::string(host) + ":" + std::to_string(port);
}

/// One TCP connection written without blocking: bytes it cannot take yet wait in `pending`.
struct Connection {
  int fd = -1;
  std::string peer;
  std::string pending;

  /// Sends what it can; "" while healthy, else why the connection is over.
  std::string flush() {
    // A peer that closed shows as readable with nothing to read.
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 0) > 0) {
      char junk[512];
      const ssize_t n = ::recv(fd, junk, sizeof junk, MSG_DONTWAIT);
      if (n == 0) return "closed by the peer";
      if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) return std::strerror(errno);
    }
    while (!pending.empty()) {
      const ssize_t n = ::send(fd, pending.data(), pending.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
      if (n > 0) {
        pending.erase(0, static_cast<std::size_t>(n));
        continue;
      }
      if (n < 0 && errno == EINTR) continue;
      if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) break;
      return n == 0 ? "closed by the peer" : std::strerror(errno);
    }
    if (pending.size() > kMaxBacklog) return "more than 1 MiB behind";
    return "";
  }

  /// Sends the pending bytes, waiting for the peer until `deadline`.
  void drain(Clock::time_point deadline) {
    while (fd >= 0 && !pending.empty() && flush().empty() && !pending.empty()) {
      const double left = std::chrono::duration<double>(deadline - Clock::now()).count();
      if (left <= 0.0) return;
      pollfd p{fd, POLLOUT, 0};
      ::poll(&p, 1, detail::pollMs(std::min(left, 0.1)));
    }
  }
};

Clock::time_point after(double s) { return Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s)); }

class FileSink final : public StreamSink {
 public:
  explicit FileSink(const StreamUrl& u) : StreamSink(u.display()) {
    if (u.type == StreamType::Stdin) {
      out_ = &std::cout;
      return;
    }
    file_.open(u.path, std::ios::binary | std::ios::trunc);
    if (!file_) throw StreamError("output '" + name() + "': cannot create the file: " + std::strerror(errno));
    out_ = &file_;
  }
  void write(std::string_view b) override {
    counters_.bytes += static_cast<std::int64_t>(b.size());
    out_->write(b.data(), static_cast<std::streamsize>(b.size()));
    out_->flush();
  }

 private:
  std::ofstream file_;
  std::ostream* out_ = nullptr;
};

class TcpServerSink final : public StreamSink {
 public:
  explicit TcpServerSink(const StreamUrl& u) : StreamSink(u.display()) {
    std::string err;
    listen_ = detail::listenTcp(u.host, u.port, 8, err);
    if (listen_ < 0) throw StreamError("output '" + name() + "': " + err);
    port_ = detail::boundPort(listen_);
  }
  ~TcpServerSink() override {
    for (auto& c : clients_) detail::closeFd(c.fd);
    detail::closeFd(listen_);
  }
  int boundPort() const override { return port_; }
  void drain(double timeout) override {
    const auto deadline = after(timeout);
    for (auto& c : clients_) c.drain(deadline);
  }

  void write(std::string_view b) override {
    acceptPending();
    counters_.bytes += static_cast<std::int64_t>(b.size());
    if (clients_.empty()) counters_.discarded += static_cast<std::int64_t>(b.size());
    for (auto& c : clients_) {
      c.pending.append(b);
      const std::string why = c.flush();
      if (!why.empty()) {
        event("output " + name() + ": client " + c.peer + " dropped: " + why);
        ++counters_.drops;
        detail::closeFd(c.fd);
      }
    }
    clients_.erase(std::remove_if(clients_.begin(), clients_.end(), [](const Connection& c) { return c.fd < 0; }), clients_.end());
  }

 private:
  void acceptPending() {
    while (detail::waitReadable(listen_, 0.0)) {
      const int fd = ::accept4(listen_, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
      if (fd < 0) return;
      boundSendBuffer(fd);
      Connection c;
      c.fd = fd;
      c.peer = peerName(fd);
      event("output " + name() + ": client " + c.peer + " connected");
      ++counters_.clients;
      clients_.push_back(std::move(c));
    }
  }

  int listen_ = -1, port_ = 0;
  std::vector<Connection> clients_;
};

class TcpClientSink final : public StreamSink {
 public:
  explicit TcpClientSink(const StreamUrl& u) : StreamSink(u.display()), host_(u.host), port_(u.port) {}
  ~TcpClientSink() override { detail::closeFd(conn_.fd); }
  void drain(double timeout) override { conn_.drain(after(timeout)); }

  void write(std::string_view b) override {
    counters_.bytes += static_cast<std::int64_t>(b.size());
    if (conn_.fd < 0 && !reconnect()) {
      counters_.discarded += static_cast<std::int64_t>(b.size());
      return;
    }
    conn_.pending.append(b);
    const std::string why = conn_.flush();
    if (why.empty()) return;
    event("output " + name() + ": connection lost: " + why);
    ++counters_.drops;
    counters_.discarded += static_cast<std::int64_t>(conn_.pending.size());
    conn_.pending.clear();
    detail::closeFd(conn_.fd);
    nextAttempt_ = Clock::now();
  }

 private:
  bool reconnect() {
    const auto now = Clock::now();
    if (now < nextAttempt_) return false;
    std::string err;
    conn_.fd = detail::connectTcp(host_, port_, 1.0, err);
    if (conn_.fd < 0) {
      event("output " + name() + ": " + err + " (next attempt in " + std::to_string(backoff_).substr(0, 4) + " s)");
      nextAttempt_ = now + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(backoff_));
      backoff_ = std::min(2.0 * backoff_, 8.0);
      return false;
    }
    boundSendBuffer(conn_.fd);
    conn_.peer = peerName(conn_.fd);
    backoff_ = 0.25;
    ++counters_.clients;
    event("output " + name() + ": connected");
    return true;
  }

  std::string host_;
  int port_;
  Connection conn_;
  Clock::time_point nextAttempt_{};
  double backoff_ = 0.25;
};

}  // namespace

StreamSink::~StreamSink() = default;

std::unique_ptr<StreamSink> StreamSink::open(const StreamUrl& url) {
  switch (url.type) {
    case StreamType::File:
    case StreamType::Stdin: return std::make_unique<FileSink>(url);
    case StreamType::TcpServer: return std::make_unique<TcpServerSink>(url);
    case StreamType::TcpClient: return std::make_unique<TcpClientSink>(url);
    case StreamType::Serial:
    case StreamType::Ntrip: break;
  }
  throw StreamError("output '" + url.display() + "': " + toString(url.type) + " is an input only (outputs: -, file, tcpsvr://, tcpcli://)");
}

std::vector<std::string> StreamSink::takeEvents() {
  std::vector<std::string> e;
  e.swap(events_);
  return e;
}

SinkOstream::Buf::Buf(StreamSink& s) : sink_(s), buf_(1 << 16) { setp(buf_.data(), buf_.data() + buf_.size()); }

int SinkOstream::Buf::sync() {
  const auto n = pptr() - pbase();
  if (n > 0) sink_.write(std::string_view(pbase(), static_cast<std::size_t>(n)));
  setp(buf_.data(), buf_.data() + buf_.size());
  return 0;
}

SinkOstream::Buf::int_type SinkOstream::Buf::overflow(int_type c) {
  sync();
  if (!traits_type::eq_int_type(c, traits_type::eof())) {
    *pptr() = traits_type::to_char_type(c);
    pbump(1);
  }
  return traits_type::not_eof(c);
}

SinkOstream::SinkOstream(StreamSink& sink) : std::ostream(nullptr), buf_(sink) { rdbuf(&buf_); }

SinkOstream::~SinkOstream() { buf_.pubsync(); }

}  // namespace gvins::rtcm
