// Output streams for live solutions (the output side of stream_source.hpp, same stream paths):
//   -   (standard output), file://PATH or a bare PATH   written and flushed as bytes come
//   tcpsvr://[ADDR]:PORT   a TCP server: every client connected gets the bytes written after it
//                          connected; clients that close or fall 1 MiB behind are dropped
//   tcpcli://HOST:PORT     a TCP client: connects at the first write, reconnects with back-off
//                          after a drop; bytes written while disconnected are discarded (counted)
// Serial ports and NTRIP are inputs only (StreamError). A sink never throws for a network
// problem: it counts it and reports it through takeEvents().
//
//   auto sink = StreamSink::open(StreamUrl::parse("tcpsvr://:5001"));
//   SinkOstream out(*sink);            // std::ostream: each flush() goes to the sink
//   out << "$GPGGA,...\r\n" << std::flush;
#pragma once

#include <cstdint>
#include <memory>
#include <ostream>
#include <streambuf>
#include <string>
#include <string_view>
#include <vector>

#include "gvins/rtcm/stream_url.hpp"

namespace gvins::rtcm {

struct SinkCounters {
  std::int64_t bytes = 0;        ///< bytes handed to write()
  std::int64_t discarded = 0;    ///< bytes no receiver got (no client, or connection down)
  std::int64_t clients = 0;      ///< connections made (accepted by a server, made by a client)
  std::int64_t drops = 0;        ///< connections lost or dropped
};

class StreamSink {
 public:
  virtual ~StreamSink();
  /// Opens `url` as an output: a file is created (StreamError if it cannot be), a TCP server
  /// binds its port at once, a TCP client connects at the first write.
  static std::unique_ptr<StreamSink> open(const StreamUrl& url);

  /// Hands `bytes` on; never blocks longer than a TCP client's connection attempt.
  virtual void write(std::string_view bytes) = 0;
  /// Waits up to `timeout` s until every receiver has taken the bytes written (at the end of a
  /// run, so that a slow client still gets the last rows); the receivers stay connected.
  virtual void drain(double timeout) { (void)timeout; }
  /// The port a TCP server is bound to (useful with port 0), else 0.
  virtual int boundPort() const { return 0; }

  const std::string& name() const { return name_; }
  const SinkCounters& counters() const { return counters_; }
  /// Connection events since the last call ("client 127.0.0.1:41122 connected", ...).
  std::vector<std::string> takeEvents();

 protected:
  explicit StreamSink(std::string name) : name_(std::move(name)) {}
  void event(std::string e) { events_.push_back(std::move(e)); }
  SinkCounters counters_;

 private:
  std::string name_;
  std::vector<std::string> events_;
};

/// A std::ostream over a sink: bytes are buffered and handed to the sink at each flush (and
/// when the buffer fills), so one flushed record reaches a TCP client in one write.
class SinkOstream : public std::ostream {
 public:
  explicit SinkOstream(StreamSink& sink);
  ~SinkOstream() override;

 private:
  class Buf : public std::streambuf {
   public:
    explicit Buf(StreamSink& s);
    int sync() override;
    int_type overflow(int_type c) override;

   private:
    StreamSink& sink_;
    std::vector<char> buf_;
  };
  Buf buf_;
};

}  // namespace gvins::rtcm
