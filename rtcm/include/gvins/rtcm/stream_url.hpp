// Stream paths in the style of RTKLIB's stream options (str2str/rtkrcv "-in"/"-out" paths; the
// syntax facts are from the RTKLIB 2.4.3 manual, appendix on stream paths):
//   file://PATH   or a bare PATH      a file (read once, to its end)
//   -   or   stdin://                 standard input (a pipe)
//   tcpcli://HOST:PORT                TCP client
//   tcpsvr://[ADDR]:PORT              TCP server accepting one client at a time (PORT 0: any free)
//   serial://DEVICE:BAUD[:8N1]        serial port, raw 8 data bits, no parity, 1 stop bit;
//                                     DEVICE without '/' is under /dev (ttyUSB0 -> /dev/ttyUSB0)
//   ntrip://[USER[:PASS]@]HOST[:PORT]/MOUNT   NTRIP client (also ntripcli://; port 2101)
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

#include "gvins/rtcm/ntrip_url.hpp"

namespace gvins::rtcm {

/// A malformed stream path, or a stream that cannot be opened; the message names the path and
/// what is wrong.
class StreamError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class StreamType { File, Stdin, TcpClient, TcpServer, Serial, Ntrip };
const char* toString(StreamType t);

struct StreamUrl {
  StreamType type = StreamType::File;
  std::string path;    ///< file path or serial device
  std::string host;    ///< TCP client host, TCP server bind address (empty: any)
  int port = 0;        ///< TCP port
  int baud = 0;        ///< serial baud rate
  NtripUrl ntrip;      ///< NTRIP caster and mountpoint

  /// Throws StreamError naming the path and the part that is wrong.
  static StreamUrl parse(std::string_view text);
  /// The path back in canonical form (NTRIP password never shown).
  std::string display() const;
};

/// Serial baud rates accepted (the POSIX/Linux termios speeds 1200..921600).
bool isSupportedBaudRate(int baud);

}  // namespace gvins::rtcm
