#include "tcp_socket.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>

#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

namespace gvins::rtcm::detail {

int pollMs(double s) { return s <= 0.0 ? 0 : static_cast<int>(std::min(s * 1000.0 + 1.0, 2.0e9)); }

bool waitReadable(int fd, double timeout) {
  pollfd p{fd, POLLIN, 0};
  for (;;) {
    const int rc = ::poll(&p, 1, pollMs(timeout));
    if (rc < 0 && errno == EINTR) continue;
    return rc > 0;
  }
}

void closeFd(int& fd) {
  if (fd >= 0) ::close(fd);
  fd = -1;
}

int listenTcp(const std::string& host, int port, int backlog, std::string& err) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE;
  addrinfo* res = nullptr;
  const int gai = ::getaddrinfo(host.empty() ? nullptr : host.c_str(), std::to_string(port).c_str(), &hints, &res);
  if (gai != 0) {
    err = "cannot resolve '" + host + "': " + gai_strerror(gai);
    return -1;
  }
  err = "no address";
  int listening = -1;
  for (addrinfo* a = res; a && listening < 0; a = a->ai_next) {
    const int fd = ::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) continue;
    const int one = 1;
    ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    if (::bind(fd, a->ai_addr, a->ai_addrlen) != 0 || ::listen(fd, backlog) != 0) {
      err = "cannot listen: " + std::string(std::strerror(errno));
      ::close(fd);
      continue;
    }
    listening = fd;
  }
  ::freeaddrinfo(res);
  if (listening < 0 && err == "no address") err = "cannot listen: no address";
  return listening;
}

int boundPort(int fd) {
  sockaddr_storage ss{};
  socklen_t len = sizeof ss;
  if (::getsockname(fd, reinterpret_cast<sockaddr*>(&ss), &len) != 0) return 0;
  return ntohs(ss.ss_family == AF_INET6 ? reinterpret_cast<sockaddr_in6*>(&ss)->sin6_port
                                        : reinterpret_cast<sockaddr_in*>(&ss)->sin_port);
}

namespace {

/// Connects `fd` (non-blocking) to `a` until `deadline`: 0, or the errno of the failure
/// (ETIMEDOUT when the deadline passed).
int connectBy(int fd, const addrinfo& a, std::chrono::steady_clock::time_point deadline) {
  if (::connect(fd, a.ai_addr, a.ai_addrlen) == 0) return 0;
  if (errno != EINPROGRESS) return errno;
  pollfd p{fd, POLLOUT, 0};
  for (;;) {
    const double left = std::chrono::duration<double>(deadline - std::chrono::steady_clock::now()).count();
    const int rc = ::poll(&p, 1, pollMs(left));
    if (rc < 0 && errno == EINTR) continue;
    if (rc <= 0) return ETIMEDOUT;
    break;
  }
  int e = 0;
  socklen_t len = sizeof e;
  ::getsockopt(fd, SOL_SOCKET, SO_ERROR, &e, &len);
  return e;
}

/// A connection to a local port nobody listens on can meet itself (TCP simultaneous open when
/// the kernel picks the destination port as the source port).
bool connectedToItself(int fd) {
  sockaddr_storage self{}, peer{};
  socklen_t ls = sizeof self, lp = sizeof peer;
  return ::getsockname(fd, reinterpret_cast<sockaddr*>(&self), &ls) == 0 &&
         ::getpeername(fd, reinterpret_cast<sockaddr*>(&peer), &lp) == 0 && ls == lp && std::memcmp(&self, &peer, ls) == 0;
}

}  // namespace

int connectTcp(const std::string& host, int port, double timeout, std::string& err, TcpConnectError* why) {
  TcpConnectError unused;
  TcpConnectError& failed = why ? *why : unused;
  failed = TcpConnectError{};
  const std::string where = host + ":" + std::to_string(port);
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* res = nullptr;
  const int gai = ::getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &res);
  if (gai != 0) {
    failed = {TcpConnectFailure::Resolve, gai_strerror(gai)};
    err = "cannot resolve '" + host + "': " + failed.reason;
    return -1;
  }
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(timeout));
  failed.reason = "no address";
  err = "cannot connect to " + where + ": " + failed.reason;
  int lastError = 0;  // of the last address that failed other than by the timeout
  bool timedOut = false;
  int connected = -1;
  for (addrinfo* a = res; a && connected < 0; a = a->ai_next) {
    const int fd = ::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC | SOCK_NONBLOCK, a->ai_protocol);
    if (fd < 0) {
      lastError = errno;
      failed.reason = std::strerror(lastError);
      err = "cannot connect to " + where + ": " + failed.reason;
      continue;
    }
    const int e = connectBy(fd, *a, deadline);
    std::string failure;
    if (e != 0) {
      failure = std::strerror(e);
      if (e == ETIMEDOUT) timedOut = true;
      else lastError = e;
    } else if (connectedToItself(fd)) {
      failure = "connected to itself (nothing listens there)";
      lastError = ECONNREFUSED;
    }
    if (!failure.empty()) {
      failed.reason = failure;
      err = "cannot connect to " + where + ": " + failure;
      ::close(fd);
      continue;
    }
    const int one = 1;
    ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    connected = fd;
  }
  ::freeaddrinfo(res);
  if (connected < 0) {
    failed.kind = lastError == ECONNREFUSED ? TcpConnectFailure::Refused
                  : timedOut                 ? TcpConnectFailure::Timeout
                                             : TcpConnectFailure::Other;
  }
  return connected;
}

}  // namespace gvins::rtcm::detail
