#include "gvins/rtcm/stream_url.hpp"

#include <array>
#include <cctype>
#include <charconv>

#include "gvins/rtcm/ntrip_error.hpp"

namespace gvins::rtcm {

namespace {

[[noreturn]] void bad(std::string_view text, const std::string& what) {
  throw StreamError("stream path '" + std::string(text) + "': " + what);
}

int parsePort(std::string_view text, std::string_view s, int minPort) {
  int v = -1;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || r.ec != std::errc() || r.ptr != s.data() + s.size() || v < minPort || v > 65535) {
    bad(text, "port '" + std::string(s) + "' is not a number in " + std::to_string(minPort) + "..65535");
  }
  return v;
}

/// HOST:PORT (IPv6 literals in brackets); host may be empty when `hostOptional`.
void hostPort(std::string_view text, std::string_view rest, bool hostOptional, int minPort, StreamUrl& u) {
  std::size_t colon;
  if (!rest.empty() && rest.front() == '[') {
    const std::size_t close = rest.find(']');
    if (close == std::string_view::npos) bad(text, "unterminated '[' in the address");
    u.host = std::string(rest.substr(1, close - 1));
    colon = close + 1;
    if (colon >= rest.size() || rest[colon] != ':') bad(text, "no ':PORT' after the address");
  } else {
    colon = rest.rfind(':');
    if (colon == std::string_view::npos) bad(text, "no ':PORT'");
    u.host = std::string(rest.substr(0, colon));
  }
  if (u.host.empty() && !hostOptional) bad(text, "no host before ':PORT'");
  for (const char c : u.host) {
    if (c == '/' || c == '@' || c == ' ' || static_cast<unsigned char>(c) < 0x20) bad(text, "invalid character in the host");
  }
  u.port = parsePort(text, rest.substr(colon + 1), minPort);
}

}  // namespace

const char* toString(StreamType t) {
  switch (t) {
    case StreamType::File: return "file";
    case StreamType::Stdin: return "stdin";
    case StreamType::TcpClient: return "tcpcli";
    case StreamType::TcpServer: return "tcpsvr";
    case StreamType::Serial: return "serial";
    case StreamType::Ntrip: return "ntrip";
  }
  return "?";
}

bool isSupportedBaudRate(int baud) {
  static constexpr std::array<int, 12> kRates{1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200, 230400, 460800, 500000, 921600};
  for (const int r : kRates) {
    if (r == baud) return true;
  }
  return false;
}

StreamUrl StreamUrl::parse(std::string_view text) {
  StreamUrl u;
  if (text.empty()) bad(text, "empty");
  if (text.find('\0') != std::string_view::npos) bad(text, "contains a NUL character");
  if (text == "-" || text == "stdin://") {
    u.type = StreamType::Stdin;
    return u;
  }
  const std::size_t sep = text.find("://");
  if (sep == std::string_view::npos) {
    u.type = StreamType::File;
    u.path = std::string(text);
    return u;
  }
  const std::string_view scheme = text.substr(0, sep);
  const std::string_view rest = text.substr(sep + 3);
  if (scheme == "file") {
    if (rest.empty()) bad(text, "no file name after file://");
    if (rest.find("::") != std::string_view::npos) bad(text, "file options ('::T', '::x') are not supported");
    u.type = StreamType::File;
    u.path = std::string(rest);
  } else if (scheme == "tcpcli") {
    u.type = StreamType::TcpClient;
    hostPort(text, rest, false, 1, u);
  } else if (scheme == "tcpsvr") {
    u.type = StreamType::TcpServer;
    hostPort(text, rest, true, 0, u);
  } else if (scheme == "serial") {
    u.type = StreamType::Serial;
    std::string_view r = rest;
    std::size_t colon = r.rfind(':');
    const auto allDigits = [](std::string_view v) {
      for (const char c : v) {
        if (!std::isdigit(static_cast<unsigned char>(c))) return false;
      }
      return true;
    };
    if (colon != std::string_view::npos && !allDigits(r.substr(colon + 1)) && r.substr(0, colon).rfind(':') != std::string_view::npos) {
      if (r.substr(colon + 1) != "8N1") bad(text, "framing '" + std::string(r.substr(colon + 1)) + "': only 8N1 is supported");
      r = r.substr(0, colon);
      colon = r.rfind(':');
    }
    if (colon == std::string_view::npos) bad(text, "no ':BAUD' after the device");
    const std::string_view dev = r.substr(0, colon), rate = r.substr(colon + 1);
    if (dev.empty()) bad(text, "no serial device");
    int baud = 0;
    const auto res = std::from_chars(rate.data(), rate.data() + rate.size(), baud);
    if (rate.empty() || res.ec != std::errc() || res.ptr != rate.data() + rate.size() || !isSupportedBaudRate(baud)) {
      bad(text, "baud rate '" + std::string(rate) + "' is not one of 1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200, 230400, 460800, 500000, 921600");
    }
    u.baud = baud;
    u.path = dev.find('/') == std::string_view::npos ? "/dev/" + std::string(dev) : std::string(dev);
  } else if (scheme == "ntrip" || scheme == "ntripcli") {
    u.type = StreamType::Ntrip;
    try {
      u.ntrip = NtripUrl::parse("ntrip://" + std::string(rest));
    } catch (const NtripError& e) {
      bad(text, e.what());
    }
    if (u.ntrip.mountpoint.empty()) bad(text, "no mountpoint ('/MOUNT')");
  } else {
    bad(text, "unknown stream type '" + std::string(scheme) + "' (file, tcpcli, tcpsvr, serial, ntrip)");
  }
  return u;
}

std::string StreamUrl::display() const {
  switch (type) {
    case StreamType::File: return "file://" + path;
    case StreamType::Stdin: return "stdin://";
    case StreamType::TcpClient: return "tcpcli://" + host + ":" + std::to_string(port);
    case StreamType::TcpServer: return "tcpsvr://" + host + ":" + std::to_string(port);
    case StreamType::Serial: return "serial://" + path + ":" + std::to_string(baud);
    case StreamType::Ntrip: return ntrip.display();
  }
  return "?";
}

}  // namespace gvins::rtcm
