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
/// A connected TCP socket (TCP_NODELAY, blocking mode as given) within `timeout` s; -1 and `err`
/// set on failure (resolution, refusal, timeout, or a connection that met itself).
int connectTcp(const std::string& host, int port, double timeout, std::string& err);

}  // namespace gvins::rtcm::detail
