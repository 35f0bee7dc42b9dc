// NTRIP client (NTRIP 1.0 and 2.0 over HTTP/1.x) on POSIX sockets: connects to a caster, asks for
// a mountpoint with HTTP Basic credentials and hands out the stream's bytes (de-chunked), ready
// to feed a gvins::rtcm::Decoder.
//
//   NtripClient c(NtripUrl::parse("ntrip://user:pass@caster:2101/MOUNT"));
//   c.connect();                      // throws NtripError: refused, 401, 404, timeout, ...
//   std::vector<std::uint8_t> buf;
//   while (c.read(buf) > 0) { decoder.feed(buf); buf.clear(); }
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "gvins/rtcm/ntrip_error.hpp"
#include "gvins/rtcm/ntrip_response.hpp"
#include "gvins/rtcm/ntrip_url.hpp"

namespace gvins::rtcm {

struct NtripOptions {
  int version = 2;                 ///< 1: "GET /MOUNT HTTP/1.0"; 2: HTTP/1.1 with Ntrip-Version
  double connectTimeout = 10.0;    ///< s, TCP connect and response header
  double readTimeout = 15.0;       ///< s without any stream data before read() gives up
  std::string userAgent = "NTRIP SRI-GVINS/0.1";
  std::string gga;                 ///< optional NMEA GGA sentence for VRS casters (sent once)
};

class NtripClient {
 public:
  explicit NtripClient(NtripUrl url, NtripOptions options = {});
  ~NtripClient();
  NtripClient(const NtripClient&) = delete;
  NtripClient& operator=(const NtripClient&) = delete;

  /// Connects, sends the request and reads the response header. Stream bytes that arrived with
  /// the header are kept for the first read(). Throws NtripError. Calling it again reconnects
  /// (e.g. after read() returned 0 or threw because the caster dropped the stream).
  void connect();
  /// Appends stream bytes to `out`, waiting up to readTimeout for at least one; returns how many
  /// were appended, 0 when the caster ended the stream. Throws NtripError (Timeout, Connection,
  /// Protocol).
  std::size_t read(std::vector<std::uint8_t>& out);
  void close();
  /// The wait of the next read() calls (s).
  void setReadTimeout(double seconds) { opt_.readTimeout = seconds; }
  /// The GGA sentence sent with the next connect() (VRS casters).
  void setGga(std::string gga) { opt_.gga = std::move(gga); }
  /// Sends text on the open connection (an updated GGA sentence for a VRS caster, CR LF
  /// included by the caller); false if not connected or the send fails.
  bool send(const std::string& text);

  /// The HTTP request that connect() sends (credentials included), for tests and logs.
  std::string request() const;
  const std::string& statusLine() const { return response_.statusLine(); }
  bool chunked() const { return response_.chunked(); }
  /// Bytes received from the socket (header and chunk framing included).
  std::int64_t bytesReceived() const { return received_; }
  const NtripUrl& url() const { return url_; }

 private:
  /// Receives into `payload` with a deadline; false on orderly close.
  bool receiveSome(std::vector<std::uint8_t>& payload, double timeout, const char* waitingFor);

  NtripUrl url_;
  NtripOptions opt_;
  NtripResponse response_;
  int fd_ = -1;
  std::vector<std::uint8_t> pending_;
  std::int64_t received_ = 0;
  bool ended_ = false;
};

}  // namespace gvins::rtcm
