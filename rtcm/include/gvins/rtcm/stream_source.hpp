// One input layer for receiver and correction streams: files, standard input, TCP client and
// server, serial ports and NTRIP casters, opened from a stream path (stream_url.hpp). A source
// hands out bytes with a timeout and counts bytes, connections, drops (gaps) and the time spent
// disconnected. Connection-based sources (TCP, serial, NTRIP) reconnect after a drop with
// exponential back-off (doubling from StreamOptions::retryInitial up to retryMax), and give up
// (End) after maxOutage seconds without a connection when that is set.
//
//   auto s = StreamSource::open(StreamUrl::parse("tcpcli://127.0.0.1:5000"));
//   std::vector<std::uint8_t> buf;
//   while (s->read(buf, 0.5) != StreamSource::Status::End) { splitter.feed(buf); buf.clear(); }
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "gvins/rtcm/stream_url.hpp"

namespace gvins::rtcm {

struct StreamOptions {
  double connectTimeout = 5.0;  ///< s, one connection attempt (TCP connect, NTRIP header)
  double retryInitial = 0.25;   ///< s, first back-off after a failed attempt or a drop
  double retryMax = 8.0;        ///< s, cap of the back-off
  /// s without a connection (after a drop, or from the start) after which the source ends;
  /// 0: retry for ever.
  double maxOutage = 0.0;
  /// s without any byte on an open connection after which it counts as dropped and is
  /// reconnected (0: never; NTRIP casters send data every second).
  double idleTimeout = 0.0;
  /// NTRIP: the rover's current GGA sentence for VRS casters (empty while unknown), sent at
  /// connection and then every ggaInterval s.
  std::function<std::string()> gga;
  double ggaInterval = 10.0;
};

struct StreamCounters {
  std::int64_t bytes = 0;
  std::int64_t connects = 0;         ///< successful connections (the first included)
  std::int64_t failedAttempts = 0;   ///< connection attempts that failed
  std::int64_t drops = 0;            ///< established connections lost: the gaps in the stream
  double gapSeconds = 0.0;           ///< time from each drop to the first byte after it
};

class StreamSource {
 public:
  enum class Status { Data, Timeout, End };
  using Clock = std::chrono::steady_clock;

  virtual ~StreamSource();
  /// Opens `url` (a TCP server binds its port at once; files and serial devices are opened at
  /// once and throw StreamError if they cannot be; network connections are made by read()).
  static std::unique_ptr<StreamSource> open(const StreamUrl& url, StreamOptions options = {});

  /// Appends the bytes available to `out`, waiting up to `timeout` s for the first: Data (at
  /// least one byte appended), Timeout, or End (file or pipe at its end, or a connection given
  /// up after maxOutage). Reconnects as needed; never throws for a dropped connection.
  Status read(std::vector<std::uint8_t>& out, double timeout);
  const std::string& name() const { return name_; }
  const StreamCounters& counters() const { return counters_; }
  /// Log lines about connections, drops and reconnections since the last call.
  std::vector<std::string> takeEvents();
  /// Steady-clock time of the last byte received (epoch of Clock if none yet).
  Clock::time_point lastByteTime() const { return lastData_; }
  /// TCP server: the port bound (useful with port 0); 0 for other sources.
  virtual int boundPort() const { return 0; }
  /// Sends bytes back over the connection when there is one (TCP, serial; NTRIP: GGA); false
  /// if not connected or not possible.
  virtual bool send(const std::string& bytes);

 protected:
  StreamSource(std::string name, StreamOptions options, bool reconnectable);
  /// One connection attempt within `timeout` s; throws StreamError on failure.
  virtual void connect(double timeout) = 0;
  /// Bytes appended (> 0), 0 on timeout, -1 when the connection or file ended.
  virtual long readSome(std::vector<std::uint8_t>& out, double timeout) = 0;
  virtual void disconnect() = 0;
  /// Called after each successful read on a connected source (NTRIP: periodic GGA).
  virtual void afterRead() {}
  const StreamOptions& options() const { return opt_; }
  void event(const std::string& text) { events_.push_back(name_ + ": " + text); }

 private:
  void dropped(const std::string& why);
  std::string name_;
  StreamOptions opt_;
  bool reconnectable_;
  bool connected_ = false, everConnected_ = false, ended_ = false;
  double backoff_;
  Clock::time_point nextAttempt_{}, outageStart_{}, lastData_{};
  bool outage_ = false, gapOpen_ = false;
  StreamCounters counters_;
  std::vector<std::string> events_;
};

}  // namespace gvins::rtcm
