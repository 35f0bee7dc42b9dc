// POSIX socket helpers shared by the stream sources and sinks (internal to gvins_rtcm).
#pragma once

#include <string>

namespace gvins::rtcm::detail {

/// Milliseconds for poll(2) from seconds (at least 1 ms for a positive wait, 0 for none).
int pollMs(double s);
/// Waits until `fd` is readable; false on timeout.
bool waitReadable(int fd, double timeout);
void closeFd(int& fd);

/// A listening TCP socket on `host` (empty: any address) and `port` (0: any free port), with
/// SO_REUSEADDR; -1 and `err` set when no address could be bound.
int listenTcp(const std::string& host, int port, int backlog, std::string& err);
/// The local port a socket is bound to.
int boundPort(int fd);
/// Why connectTcp failed.
enum class TcpConnectFailure {
  None,
  Resolve,  ///< the host name cannot be resolved
  Refused,  ///< nothing listens there (connection refused, or a connection that met itself)
  Timeout,  ///< no answer within the timeout
  Other,    ///< any other socket error
};
struct TcpConnectError {
  TcpConnectFailure kind = TcpConnectFailure::None;
  std::string reason;  ///< the resolver's or the last address's error text
};

/// A connected, non-blocking TCP socket (TCP_NODELAY) to `host`:`port`, trying the host's
/// addresses in turn within `timeout` s for all of them. On failure -1, `err` set to a message
/// naming host:port and the last address's error, and `why` (if given) to the kind: Refused if
/// the last address that failed other than by the timeout refused, else Timeout if one timed
/// out, else Resolve or Other.
int connectTcp(const std::string& host, int port, double timeout, std::string& err, TcpConnectError* why = nullptr);

}  // namespace gvins::rtcm::detail
