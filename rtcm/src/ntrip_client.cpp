#include "gvins/rtcm/ntrip_client.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>

#include <poll.h>
#include <sys/socket.h>
#include <sys/types.h>
#include <unistd.h>

#include "tcp_socket.hpp"

namespace gvins::rtcm {
namespace {

using Kind = NtripError::Kind;
using Clock = std::chrono::steady_clock;

double secondsLeft(Clock::time_point deadline) {
  return std::chrono::duration<double>(deadline - Clock::now()).count();
}

using detail::pollMs;

}  // namespace

NtripClient::NtripClient(NtripUrl url, NtripOptions options)
    : url_(std::move(url)), opt_(std::move(options)), response_(url_.mountpoint) {}

NtripClient::~NtripClient() { close(); }

void NtripClient::close() { detail::closeFd(fd_); }

std::string NtripClient::request() const {
  std::string r;
  if (opt_.version == 1) {
    r = "GET /" + url_.mountpoint + " HTTP/1.0\r\n";
  } else {
    r = "GET /" + url_.mountpoint + " HTTP/1.1\r\n";
    r += "Host: " + url_.host + ":" + std::to_string(url_.port) + "\r\n";
    r += "Ntrip-Version: Ntrip/2.0\r\n";
  }
  r += "User-Agent: " + opt_.userAgent + "\r\n";
  if (!url_.user.empty() || !url_.password.empty()) {
    r += "Authorization: Basic " + base64Encode(url_.user + ":" + url_.password) + "\r\n";
  }
  if (opt_.version != 1 && !opt_.gga.empty()) r += "Ntrip-GGA: " + opt_.gga + "\r\n";
  if (opt_.version != 1) r += "Connection: close\r\n";
  r += "\r\n";
  if (opt_.version == 1 && !opt_.gga.empty()) r += opt_.gga + "\r\n";
  return r;
}

void NtripClient::connect() {
  close();
  // A fresh exchange (connect() also reconnects after a dropped stream).
  response_ = NtripResponse(url_.mountpoint);
  pending_.clear();
  ended_ = false;
  const std::string where = url_.host + ":" + std::to_string(url_.port);
  // One deadline for the connection, the request and the response header.
  const Clock::time_point deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(opt_.connectTimeout));
  std::string err;
  detail::TcpConnectError why;
  fd_ = detail::connectTcp(url_.host, url_.port, opt_.connectTimeout, err, &why);
  if (fd_ < 0) {
    switch (why.kind) {
      case detail::TcpConnectFailure::Resolve:
        throw NtripError(Kind::Resolve, "cannot resolve caster host '" + url_.host + "': " + why.reason);
      case detail::TcpConnectFailure::Refused:
        throw NtripError(Kind::ConnectionRefused, "connection to caster " + where + " refused (nothing listens there)");
      case detail::TcpConnectFailure::Timeout:
        throw NtripError(Kind::Timeout, "no connection to caster " + where + " within " + std::to_string(opt_.connectTimeout) + " s");
      default: throw NtripError(Kind::Connection, "cannot connect to caster " + where + ": " + why.reason);
    }
  }

  // Send the request.
  const std::string req = request();
  std::size_t sent = 0;
  while (sent < req.size()) {
    const ssize_t n = ::send(fd_, req.data() + sent, req.size() - sent, MSG_NOSIGNAL);
    if (n > 0) {
      sent += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
      pollfd p{fd_, POLLOUT, 0};
      if (::poll(&p, 1, pollMs(secondsLeft(deadline))) <= 0) {
        close();
        throw NtripError(Kind::Timeout, "caster " + where + " did not accept the request within " + std::to_string(opt_.connectTimeout) + " s");
      }
      continue;
    }
    const int e = errno;
    close();
    throw NtripError(Kind::Connection, "sending the request to " + where + " failed: " + std::strerror(e));
  }

  // Response header (stream bytes that follow it are kept).
  try {
    while (!response_.headerComplete()) {
      const double left = secondsLeft(deadline);
      if (left <= 0.0) throw NtripError(Kind::Timeout, "caster " + where + " sent no complete response within " + std::to_string(opt_.connectTimeout) + " s");
      if (!receiveSome(pending_, left, "the response header")) {
        response_.end();
        throw NtripError(Kind::Connection, "caster " + where + " closed the connection after its header");
      }
    }
  } catch (...) {
    close();
    throw;
  }
}

bool NtripClient::receiveSome(std::vector<std::uint8_t>& payload, double timeout, const char* waitingFor) {
  const Clock::time_point deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout));
  std::uint8_t buf[16384];
  for (;;) {
    pollfd p{fd_, POLLIN, 0};
    const int rc = ::poll(&p, 1, pollMs(secondsLeft(deadline)));
    if (rc < 0 && errno == EINTR) continue;
    if (rc == 0) {
      throw NtripError(Kind::Timeout, "nothing received from " + url_.host + ":" + std::to_string(url_.port) +
                                          " for " + std::to_string(timeout) + " s while waiting for " + waitingFor);
    }
    const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
    if (n > 0) {
      received_ += n;
      response_.feed({buf, static_cast<std::size_t>(n)}, payload);
      return true;
    }
    if (n == 0) return false;
    if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) continue;
    throw NtripError(Kind::Connection, std::string("receiving from the caster failed: ") + std::strerror(errno));
  }
}

std::size_t NtripClient::read(std::vector<std::uint8_t>& out) {
  if (!pending_.empty()) {
    const std::size_t n = pending_.size();
    out.insert(out.end(), pending_.begin(), pending_.end());
    pending_.clear();
    return n;
  }
  if (fd_ < 0 || ended_) return 0;
  const Clock::time_point deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(opt_.readTimeout));
  for (;;) {
    const std::size_t before = out.size();
    if (response_.finished()) {
      ended_ = true;
      return 0;
    }
    const double left = secondsLeft(deadline);
    if (left <= 0.0) throw NtripError(Kind::Timeout, "no stream data from " + url_.display() + " for " + std::to_string(opt_.readTimeout) + " s");
    if (!receiveSome(out, left, "stream data")) {
      ended_ = true;
      response_.end();
      return out.size() - before;
    }
    if (out.size() > before) return out.size() - before;  // chunk framing alone gives nothing yet
  }
}

bool NtripClient::send(const std::string& text) {
  if (fd_ < 0 || ended_) return false;
  std::size_t sent = 0;
  while (sent < text.size()) {
    const ssize_t n = ::send(fd_, text.data() + sent, text.size() - sent, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n <= 0) return false;
    sent += static_cast<std::size_t>(n);
  }
  return true;
}

}  // namespace gvins::rtcm
