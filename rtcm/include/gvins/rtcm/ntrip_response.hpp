// The caster's side of an NTRIP exchange, as a byte-stream parser independent of sockets (so it
// is unit-tested and fuzzed on its own): the status line and headers, then the stream payload.
//
// Accepted success responses: "ICY 200 OK" (NTRIP 1.0; casters such as RTKLIB's also answer
// version 2 requests this way), optionally followed by header lines, and "HTTP/1.x 200 OK" with
// headers (NTRIP 2.0), the body raw or in HTTP/1.1 chunked transfer coding (RFC 9112, 7.1).
// Failures become NtripError: 401 Unauthorized, 404 or a source table instead of the stream
// (NTRIP 1.0 "SOURCETABLE 200 OK", or 200 with Content-Type gnss/sourcetable) as
// MountpointNotFound listing the caster's mountpoints, other statuses as HttpStatus, malformed
// headers or chunks as Protocol. Header size and chunk sizes are bounded.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace gvins::rtcm {

class NtripResponse {
 public:
  /// `mountpoint` is named in error messages.
  explicit NtripResponse(std::string mountpoint = {}) : mount_(std::move(mountpoint)) {}

  /// Consumes received bytes and appends stream payload to `payload`. Throws NtripError as
  /// described above (at the point where the failure is known).
  void feed(std::span<const std::uint8_t> bytes, std::vector<std::uint8_t>& payload);
  /// The connection was closed by the caster. Throws if this ends the exchange badly (no or
  /// incomplete header, a source table, a chunk cut short).
  void end();

  /// The caster accepted the request: the stream may follow (after "ICY 200 OK" optional header
  /// lines are still recognised and stripped when stream bytes arrive).
  bool headerComplete() const {
    return state_ == State::IcyHeaders || (state_ >= State::Raw && state_ != State::SourceTable);
  }
  /// First line of the response ("ICY 200 OK", "HTTP/1.1 200 OK").
  const std::string& statusLine() const { return statusLine_; }
  bool chunked() const { return chunked_; }
  /// True once the final zero-size chunk has been read.
  bool finished() const { return state_ == State::Done; }

  static constexpr std::size_t kMaxHeader = 16384;
  static constexpr std::size_t kMaxSourceTable = 1 << 20;

 private:
  enum class State { Status, Headers, IcyHeaders, SourceTable, Raw, ChunkSize, ChunkData, ChunkEnd, Trailer, Done };
  void parseStatus(const std::string& line);
  void parseHeader(const std::string& line);
  void finishHeaders();
  [[noreturn]] void failSourceTable();
  /// Takes a line (without CR LF) from buf_ at pos; false if no complete line yet.
  bool takeLine(std::string& line, std::size_t limit, const char* what);

  std::string mount_;
  State state_ = State::Status;
  std::string buf_;  // undecoded bytes (header text, chunk framing)
  std::size_t headerBytes_ = 0;
  std::string statusLine_;
  int status_ = 0;
  bool chunked_ = false;
  bool sourceTableType_ = false;
  std::uint64_t chunkLeft_ = 0;
  std::string table_;
};

}  // namespace gvins::rtcm
