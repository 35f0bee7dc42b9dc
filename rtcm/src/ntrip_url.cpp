#include "gvins/rtcm/ntrip_url.hpp"

#include <cctype>

#include "gvins/rtcm/ntrip_error.hpp"

namespace gvins::rtcm {
namespace {

[[noreturn]] void bad(std::string_view url, const std::string& what) {
  throw NtripError(NtripError::Kind::BadUrl, "bad NTRIP URL '" + std::string(url) + "': " + what);
}

int hexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

std::string percentDecode(std::string_view s, std::string_view url) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%') {
      if (i + 2 >= s.size()) bad(url, "incomplete percent escape");
      const int a = hexValue(s[i + 1]), b = hexValue(s[i + 2]);
      if (a < 0 || b < 0) bad(url, "bad percent escape");
      out.push_back(static_cast<char>(a * 16 + b));
      i += 2;
    } else {
      out.push_back(s[i]);
    }
  }
  return out;
}

}  // namespace

NtripUrl NtripUrl::parse(std::string_view url) {
  NtripUrl u;
  std::string_view rest = url;
  for (std::string_view scheme : {"ntrip://", "http://"}) {
    if (rest.substr(0, scheme.size()) == scheme) {
      rest.remove_prefix(scheme.size());
      break;
    }
  }
  if (rest.find("://") != std::string_view::npos) bad(url, "only ntrip:// and http:// are supported");
  const std::size_t slash = rest.find('/');
  std::string_view authority = rest.substr(0, slash);
  if (slash != std::string_view::npos) u.mountpoint = std::string(rest.substr(slash + 1));
  const std::size_t at = authority.rfind('@');
  if (at != std::string_view::npos) {
    const std::string_view cred = authority.substr(0, at);
    const std::size_t colon = cred.find(':');
    u.user = percentDecode(cred.substr(0, colon), url);
    if (colon != std::string_view::npos) u.password = percentDecode(cred.substr(colon + 1), url);
    authority.remove_prefix(at + 1);
  }
  const std::size_t colon = authority.rfind(':');
  if (colon != std::string_view::npos && authority.find(']') == std::string_view::npos) {
    const std::string_view p = authority.substr(colon + 1);
    if (p.empty() || p.size() > 5) bad(url, "bad port");
    int port = 0;
    for (char c : p) {
      if (!std::isdigit(static_cast<unsigned char>(c))) bad(url, "port is not a number");
      port = port * 10 + (c - '0');
    }
    if (port < 1 || port > 65535) bad(url, "port out of range");
    u.port = port;
    authority = authority.substr(0, colon);
  }
  if (authority.empty()) bad(url, "no host");
  u.host = std::string(authority);
  for (char c : u.mountpoint) {
    if (static_cast<unsigned char>(c) <= ' ' || c == '/') bad(url, "mountpoint contains a blank, control character or '/'");
  }
  return u;
}

std::string NtripUrl::display() const {
  std::string s = "ntrip://";
  if (!user.empty()) s += user + "@";
  return s + host + ":" + std::to_string(port) + "/" + mountpoint;
}

std::string base64Encode(std::string_view data) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::size_t i = 0;
  for (; i + 3 <= data.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(data[i]) << 16) |
                       (static_cast<unsigned char>(data[i + 1]) << 8) |
                       static_cast<unsigned char>(data[i + 2]);
    for (int k = 3; k >= 0; --k) out.push_back(kAlphabet[(v >> (6 * k)) & 63]);
  }
  const std::size_t left = data.size() - i;
  if (left > 0) {
    unsigned v = static_cast<unsigned char>(data[i]) << 16;
    if (left == 2) v |= static_cast<unsigned char>(data[i + 1]) << 8;
    out.push_back(kAlphabet[(v >> 18) & 63]);
    out.push_back(kAlphabet[(v >> 12) & 63]);
    out.push_back(left == 2 ? kAlphabet[(v >> 6) & 63] : '=');
    out.push_back('=');
  }
  return out;
}

}  // namespace gvins::rtcm
