// NTRIP URL: ntrip://[user[:password]@]host[:port]/mountpoint (also http://). Port 2101 by
// default (IANA-registered NTRIP port). User and password may be percent-encoded.
#pragma once

#include <string>
#include <string_view>

namespace gvins::rtcm {

struct NtripUrl {
  std::string user;
  std::string password;
  std::string host;
  int port = 2101;
  std::string mountpoint;  ///< without the leading '/'; empty asks for the source table

  /// Throws NtripError(BadUrl) naming what is wrong.
  static NtripUrl parse(std::string_view url);
  /// "ntrip://user@host:port/MOUNT" (password never shown).
  std::string display() const;
};

/// RFC 4648 base64 (for the HTTP Basic Authorization header).
std::string base64Encode(std::string_view data);

}  // namespace gvins::rtcm
