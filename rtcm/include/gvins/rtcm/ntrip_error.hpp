// Errors of the NTRIP client, with a kind a caller can act on (retry, fix credentials, ...).
#pragma once

#include <stdexcept>
#include <string>

namespace gvins::rtcm {

class NtripError : public std::runtime_error {
 public:
  enum class Kind {
    BadUrl,             ///< the URL cannot be parsed
    Resolve,            ///< host name not found
    ConnectionRefused,  ///< nothing listens on host:port
    Connection,         ///< other socket error, or the caster closed the connection early
    Timeout,            ///< connect, response or data timeout
    Unauthorized,       ///< HTTP 401: wrong user or password
    MountpointNotFound, ///< HTTP 404, or a source table instead of the stream
    HttpStatus,         ///< any other non-200 status
    Protocol,           ///< malformed response (header, chunked encoding)
  };
  NtripError(Kind kind, const std::string& what) : std::runtime_error(what), kind_(kind) {}
  Kind kind() const { return kind_; }

 private:
  Kind kind_;
};

}  // namespace gvins::rtcm
