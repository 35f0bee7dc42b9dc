// NTRIP: URL and base64, the response parser (ICY, HTTP with chunked transfer coding, errors),
// the client against a scripted loopback caster (chunks, timeouts, refused connections) and
// against RTKLIB's str2str as a real NTRIP caster serving an RTCM log.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <random>
#include <thread>

#include "gvins/rtcm/decoder.hpp"
#include "gvins/rtcm/ntrip_client.hpp"
#include "independent_frame_scan.hpp"

namespace gvins::rtcm {
namespace {

using testing::dataDir;
using testing::readBytes;
using Kind = NtripError::Kind;

std::vector<std::uint8_t> bytesOf(std::string_view s) { return {s.begin(), s.end()}; }

/// Runs `f` and returns the kind of the NtripError it throws (fails the test if none).
template <class F>
std::pair<Kind, std::string> errorOf(F&& f) {
  try {
    f();
  } catch (const NtripError& e) {
    return {e.kind(), e.what()};
  }
  ADD_FAILURE() << "no NtripError thrown";
  return {Kind::Protocol, ""};
}

TEST(NtripUrl, ParsesAllParts) {
  const NtripUrl u = NtripUrl::parse("ntrip://alice:s%3Acret@caster.example.org:2102/MOUNT1");
  EXPECT_EQ(u.user, "alice");
  EXPECT_EQ(u.password, "s:cret");
  EXPECT_EQ(u.host, "caster.example.org");
  EXPECT_EQ(u.port, 2102);
  EXPECT_EQ(u.mountpoint, "MOUNT1");
  EXPECT_EQ(u.display(), "ntrip://alice@caster.example.org:2102/MOUNT1");
  const NtripUrl d = NtripUrl::parse("caster:80/RTCM3");
  EXPECT_EQ(d.host, "caster");
  EXPECT_EQ(d.port, 80);
  EXPECT_TRUE(d.user.empty());
  EXPECT_EQ(NtripUrl::parse("ntrip://h/M").port, 2101);
  EXPECT_EQ(NtripUrl::parse("http://u:p@h:1/M").user, "u");
  for (const char* bad : {"ntrip://:2101/M", "ntrip://h:99999/M", "ntrip://h:x/M", "ftp://h/M", "ntrip://h/M N", "ntrip://u:%zz@h/M"}) {
    EXPECT_EQ(errorOf([&] { NtripUrl::parse(bad); }).first, Kind::BadUrl) << bad;
  }
}

TEST(NtripUrl, Base64Rfc4648Vectors) {
  // RFC 4648, section 10.
  EXPECT_EQ(base64Encode(""), "");
  EXPECT_EQ(base64Encode("f"), "Zg==");
  EXPECT_EQ(base64Encode("fo"), "Zm8=");
  EXPECT_EQ(base64Encode("foo"), "Zm9v");
  EXPECT_EQ(base64Encode("foob"), "Zm9vYg==");
  EXPECT_EQ(base64Encode("fooba"), "Zm9vYmE=");
  EXPECT_EQ(base64Encode("foobar"), "Zm9vYmFy");
}

/// Feeds `text` into a fresh parser in random pieces; returns the payload.
std::vector<std::uint8_t> parseInPieces(const std::vector<std::uint8_t>& text, unsigned seed, bool end = true) {
  NtripResponse r("MNT");
  std::vector<std::uint8_t> payload;
  std::mt19937 rng(seed);
  std::size_t pos = 0;
  while (pos < text.size()) {
    const std::size_t n = std::min<std::size_t>(1 + rng() % 50, text.size() - pos);
    r.feed({text.data() + pos, n}, payload);
    pos += n;
  }
  if (end) r.end();
  return payload;
}

std::vector<std::uint8_t> chunked(const std::vector<std::uint8_t>& data, unsigned seed) {
  std::mt19937 rng(seed);
  std::string out;
  std::size_t pos = 0;
  while (pos < data.size()) {
    const std::size_t n = std::min<std::size_t>(1 + rng() % 3000, data.size() - pos);
    char size[32];
    std::snprintf(size, sizeof size, rng() % 2 ? "%zx" : "%zX", n);
    out += size;
    if (rng() % 4 == 0) out += ";ext=1";  // chunk extensions are allowed and ignored
    out += "\r\n";
    out.append(reinterpret_cast<const char*>(data.data() + pos), n);
    out += "\r\n";
    pos += n;
  }
  out += "0\r\nX-Trailer: 1\r\n\r\n";
  return bytesOf(out);
}

TEST(NtripResponse, IcyAndChunkedStreamsYieldTheExactBytes) {
  const auto data = readBytes(dataDir() / "rtcm/rtklib_testglo.rtcm3");
  // NTRIP 1.0: "ICY 200 OK" then the stream; the stream here even starts with ASCII text.
  auto icy = bytesOf("ICY 200 OK\r\n");
  icy.insert(icy.end(), data.begin(), data.end());
  for (unsigned seed : {1u, 2u, 3u}) EXPECT_EQ(parseInPieces(icy, seed), data);
  // ICY with header lines (some casters send them).
  auto icyh = bytesOf("ICY 200 OK\r\nServer: caster\r\nContent-Type: gnss/data\r\n\r\n");
  const auto binary = readBytes(dataDir() / "rtcm/rtklib_GMSD7_20121014.rtcm3");
  icyh.insert(icyh.end(), binary.begin(), binary.end());
  EXPECT_EQ(parseInPieces(icyh, 4), binary);
  // NTRIP 2.0 chunked.
  for (unsigned seed : {5u, 6u, 7u}) {
    auto http = bytesOf("HTTP/1.1 200 OK\r\nNtrip-Version: Ntrip/2.0\r\nContent-Type: gnss/data\r\nTransfer-Encoding: chunked\r\n\r\n");
    const auto body = chunked(data, seed);
    http.insert(http.end(), body.begin(), body.end());
    NtripResponse r("MNT");
    std::vector<std::uint8_t> payload;
    r.feed(http, payload);
    EXPECT_TRUE(r.chunked());
    EXPECT_TRUE(r.finished());
    EXPECT_EQ(payload, data);
    EXPECT_EQ(parseInPieces(http, seed), data);
  }
  // NTRIP 2.0 without chunking.
  auto plain = bytesOf("HTTP/1.1 200 OK\r\nContent-Type: gnss/data\r\n\r\n");
  plain.insert(plain.end(), data.begin(), data.end());
  EXPECT_EQ(parseInPieces(plain, 8), data);
}

TEST(NtripResponse, ErrorsAreClassified) {
  auto kindOf = [](std::string_view text, bool end = true) {
    return errorOf([&] { parseInPieces(bytesOf(text), 9, end); });
  };
  auto [k401, m401] = kindOf("HTTP/1.0 401 Unauthorized\r\n\r\n");
  EXPECT_EQ(k401, Kind::Unauthorized);
  EXPECT_NE(m401.find("'MNT'"), std::string::npos) << m401;
  EXPECT_EQ(kindOf("HTTP/1.1 404 Not Found\r\n\r\n").first, Kind::MountpointNotFound);
  auto [kst, mst] = kindOf("SOURCETABLE 200 OK\r\nContent-Type: text/plain\r\n\r\nSTR;AAA;x\r\nSTR;BBB;y\r\nENDSOURCETABLE\r\n");
  EXPECT_EQ(kst, Kind::MountpointNotFound);
  EXPECT_NE(mst.find("AAA, BBB"), std::string::npos) << mst;
  EXPECT_EQ(kindOf("HTTP/1.1 200 OK\r\nContent-Type: gnss/sourcetable\r\n\r\nSTR;C;\r\nENDSOURCETABLE\r\n").first,
            Kind::MountpointNotFound);
  EXPECT_EQ(kindOf("HTTP/1.1 503 Service Unavailable\r\n\r\n").first, Kind::HttpStatus);
  EXPECT_EQ(kindOf("SSH-2.0-OpenSSH\r\n").first, Kind::Protocol);
  EXPECT_EQ(kindOf("HTTP/1.1 200 OK\r\nTransfer-Encoding: chunked\r\n\r\nzz\r\n").first, Kind::Protocol);
  EXPECT_EQ(kindOf("HTTP/1.1 200 OK\r\nTransfer-Encoding: chunked\r\n\r\n10\r\nabc").first, Kind::Protocol);
  EXPECT_EQ(kindOf("HTTP/1.1 200 OK\r\nTransfer-Encoding: chunked\r\n\r\n3\r\nabcXY").first, Kind::Protocol);
  EXPECT_EQ(kindOf("HTTP/1.1 200 OK\r\nBroken header\r\n\r\n").first, Kind::Protocol);
  EXPECT_EQ(kindOf("").first, Kind::Connection);
  EXPECT_EQ(kindOf("HTTP/1.1 200 OK\r\nServer: x\r\n").first, Kind::Connection);
  // RTKLIB's caster sends only the status line of an error before closing.
  EXPECT_EQ(kindOf("HTTP/1.0 401 Unauthorized\r\n").first, Kind::Unauthorized);
  EXPECT_EQ(kindOf(std::string(20000, 'A')).first, Kind::Protocol);  // no line end: bounded
  std::string many = "HTTP/1.1 200 OK\r\n";
  for (int i = 0; i < 2000; ++i) many += "X-Filler: 0123456789\r\n";
  EXPECT_EQ(kindOf(many).first, Kind::Protocol);
}

TEST(NtripResponse, SourceTableEndIsFoundAcrossPieces) {
  // The end marker is searched in the new bytes only: it must still be found when it straddles
  // pieces, at exactly the byte that completes it, and not before.
  const std::string head = "SOURCETABLE 200 OK\r\n\r\n";
  const std::string table = "STR;AAA;x\r\nSTR;ENDSOURCETABL;y\r\nSTR;BBB;z\r\nENDSOURCETABLE\r\n";
  const std::string text = head + table;
  const std::size_t last = text.rfind("ENDSOURCETABLE") + std::string_view("ENDSOURCETABLE").size() - 1;
  for (std::size_t piece : {std::size_t{1}, std::size_t{2}, std::size_t{5}, std::size_t{13}, std::size_t{14}}) {
    NtripResponse r("MNT");
    std::vector<std::uint8_t> payload;
    std::size_t thrownAt = 0;
    std::string message;
    try {
      for (std::size_t pos = 0; pos < text.size(); pos += piece) {
        thrownAt = std::min(pos + piece, text.size()) - 1;
        r.feed(bytesOf(std::string_view(text).substr(pos, piece)), payload);
      }
    } catch (const NtripError& e) {
      EXPECT_EQ(e.kind(), Kind::MountpointNotFound);
      message = e.what();
    }
    // The piece that holds the marker's last byte is the one that throws.
    EXPECT_EQ(thrownAt, std::min(last / piece * piece + piece, text.size()) - 1)
        << "piece " << piece;
    EXPECT_NE(message.find("3 mountpoints: AAA, ENDSOURCETABL, BBB"), std::string::npos) << message;
  }
}

// ---- a scripted caster on loopback -------------------------------------------------------------

class ScriptedCaster {
 public:
  /// Accepts `connections` connections one after the other; on each reads the request, sends
  /// `reply` (unless empty) and closes after `holdSeconds`.
  ScriptedCaster(std::vector<std::uint8_t> reply, double holdSeconds = 0.0, int connections = 1) {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = 0;
    EXPECT_EQ(::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
    socklen_t len = sizeof a;
    ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len);
    port_ = ntohs(a.sin_port);
    ::listen(fd_, 4);
    thread_ = std::thread([this, reply = std::move(reply), holdSeconds, connections] {
      for (int k = 0; k < connections; ++k) serve(reply, holdSeconds);
    });
  }

  ~ScriptedCaster() {
    ::shutdown(fd_, SHUT_RDWR);
    ::close(fd_);
    if (thread_.joinable()) thread_.join();
  }
  int port() const { return port_; }
  std::string request() {
    if (thread_.joinable()) thread_.join();
    return request_;
  }

 private:
  void serve(const std::vector<std::uint8_t>& reply, double holdSeconds) {
    {
      const int c = ::accept(fd_, nullptr, nullptr);
      if (c < 0) return;
      char buf[4096];
      std::string req;
      while (req.find("\r\n\r\n") == std::string::npos) {
        const ssize_t n = ::recv(c, buf, sizeof buf, 0);
        if (n <= 0) break;
        req.append(buf, static_cast<std::size_t>(n));
      }
      request_ = req;
      std::size_t sent = 0;
      while (sent < reply.size()) {
        const ssize_t n = ::send(c, reply.data() + sent, std::min<std::size_t>(1500, reply.size() - sent), MSG_NOSIGNAL);
        if (n <= 0) break;
        sent += static_cast<std::size_t>(n);
      }
      std::this_thread::sleep_for(std::chrono::duration<double>(holdSeconds));
      ::close(c);
    }
  }

  int fd_ = -1;
  int port_ = 0;
  std::thread thread_;
  std::string request_;
};

/// Reads a whole stream into a decoder; returns the frames.
std::int64_t receiveAll(NtripClient& c, Decoder& dec) {
  std::vector<std::uint8_t> buf;
  while (c.read(buf) > 0) {
    dec.feed(buf);
    buf.clear();
    while (dec.poll()) {
    }
  }
  dec.finish();
  return dec.stats().framing.frames;
}

TEST(NtripClient, ChunkedNtrip2StreamFromScriptedCaster) {
  const auto data = readBytes(dataDir() / "rtcm/rtklib_GMSD7_20121014.rtcm3");
  auto reply = bytesOf("HTTP/1.1 200 OK\r\nNtrip-Version: Ntrip/2.0\r\nTransfer-Encoding: chunked\r\n\r\n");
  const auto body = chunked(data, 11);
  reply.insert(reply.end(), body.begin(), body.end());
  ScriptedCaster caster(reply);
  NtripClient c(NtripUrl::parse("ntrip://bob:pw@127.0.0.1:" + std::to_string(caster.port()) + "/GMSD"));
  c.connect();
  EXPECT_TRUE(c.chunked());
  Decoder dec;
  EXPECT_EQ(receiveAll(c, dec), testing::independentScan(data).frames);
  const std::string req = caster.request();
  EXPECT_EQ(req.rfind("GET /GMSD HTTP/1.1\r\n", 0), 0u) << req;
  EXPECT_NE(req.find("Ntrip-Version: Ntrip/2.0\r\n"), std::string::npos);
  EXPECT_NE(req.find("Authorization: Basic " + base64Encode("bob:pw") + "\r\n"), std::string::npos);
}

TEST(NtripClient, Ntrip1RequestAndIcyAnswer) {
  const auto data = readBytes(dataDir() / "rtcm/rtklib_testglo.rtcm3");
  auto reply = bytesOf("ICY 200 OK\r\n");
  reply.insert(reply.end(), data.begin(), data.end());
  ScriptedCaster caster(reply);
  NtripOptions o;
  o.version = 1;
  NtripClient c(NtripUrl::parse("ntrip://u:p@127.0.0.1:" + std::to_string(caster.port()) + "/TG"), o);
  c.connect();
  Decoder dec;
  EXPECT_EQ(receiveAll(c, dec), 429);
  EXPECT_EQ(c.statusLine(), "ICY 200 OK");
  const std::string req = caster.request();
  EXPECT_EQ(req.rfind("GET /TG HTTP/1.0\r\n", 0), 0u) << req;
  EXPECT_EQ(req.find("Ntrip-Version"), std::string::npos);

}

TEST(NtripClient, ReconnectsAfterTheStreamEnds) {
  const auto data = readBytes(dataDir() / "rtcm/rtklib_testglo.rtcm3");
  auto reply = bytesOf("ICY 200 OK\r\n");
  reply.insert(reply.end(), data.begin(), data.end());
  ScriptedCaster caster(reply, 0.0, 2);
  NtripClient c(NtripUrl::parse("ntrip://u:p@127.0.0.1:" + std::to_string(caster.port()) + "/TG"));
  for (int session = 0; session < 2; ++session) {
    c.connect();
    Decoder dec;
    EXPECT_EQ(receiveAll(c, dec), 429) << "session " << session;
  }
}

TEST(NtripClient, TimeoutsAndRefusedConnections) {
  // A caster that accepts but never answers: the response timeout fires.
  {
    ScriptedCaster silent({}, 1.0);
    NtripOptions o;
    o.connectTimeout = 0.4;
    NtripClient c(NtripUrl::parse("ntrip://127.0.0.1:" + std::to_string(silent.port()) + "/M"), o);
    const auto t0 = std::chrono::steady_clock::now();
    const auto [kind, msg] = errorOf([&] { c.connect(); });
    EXPECT_EQ(kind, Kind::Timeout) << msg;
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 2.0);
  }
  // A stream that stops sending: the read timeout fires.
  {
    ScriptedCaster stalls(bytesOf("ICY 200 OK\r\n\xD3"), 1.0);
    NtripOptions o;
    o.readTimeout = 0.3;
    NtripClient c(NtripUrl::parse("ntrip://127.0.0.1:" + std::to_string(stalls.port()) + "/M"), o);
    c.connect();
    std::vector<std::uint8_t> buf;
    std::size_t got = c.read(buf);  // the byte that came with the header
    EXPECT_EQ(got, 1u);
    const auto [kind, msg] = errorOf([&] { c.read(buf); });
    EXPECT_EQ(kind, Kind::Timeout) << msg;
  }
  // Nothing listens: refused.
  {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
    socklen_t len = sizeof a;
    ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
    const int port = ntohs(a.sin_port);
    ::close(fd);
    NtripClient c(NtripUrl::parse("ntrip://127.0.0.1:" + std::to_string(port) + "/M"));
    const auto [kind, msg] = errorOf([&] { c.connect(); });
    EXPECT_EQ(kind, Kind::ConnectionRefused) << msg;
    EXPECT_NE(msg.find("refused"), std::string::npos);
  }
  // Unknown host.
  {
    NtripClient c(NtripUrl::parse("ntrip://no-such-host.invalid/M"));
    EXPECT_EQ(errorOf([&] { c.connect(); }).first, Kind::Resolve);
  }
}

// ---- RTKLIB str2str as the caster ------------------------------------------------------------

/// str2str 2.4.3 b34 as an NTRIP caster ("-out ntripc://user:passwd@:port/mntpnt") reading the
/// stream from its standard input, which the test writes once the client is connected. (The
/// caster answers "ICY 200 OK" and then sends nothing until data arrives: the client must not
/// wait for more header after that line.)
class Str2StrCaster {
 public:
  Str2StrCaster(int port, const std::string& user, const std::string& pass, const std::string& mount) {
    int p[2];
    EXPECT_EQ(::pipe(p), 0);
    const std::string out = "ntripc://" + user + ":" + pass + "@:" + std::to_string(port) + "/" + mount;
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(p[0], 0);
      ::close(p[0]);
      ::close(p[1]);
      const int devnull = ::open("/dev/null", O_WRONLY);
      ::dup2(devnull, 2);
      ::execlp("str2str", "str2str", "-out", out.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
    ::close(p[0]);
    in_ = p[1];
  }
  ~Str2StrCaster() {
    if (in_ >= 0) ::close(in_);
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      int status = 0;
      ::waitpid(pid_, &status, 0);
    }
  }
  void write(const std::vector<std::uint8_t>& d) {
    std::size_t sent = 0;
    while (sent < d.size()) {
      const ssize_t n = ::write(in_, d.data() + sent, d.size() - sent);
      ASSERT_GT(n, 0);
      sent += static_cast<std::size_t>(n);
    }
  }
  bool running() const {
    int status = 0;
    return ::waitpid(pid_, &status, WNOHANG) == 0;
  }

 private:
  pid_t pid_ = -1;
  int in_ = -1;
};

int freePort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
  socklen_t len = sizeof a;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  ::close(fd);
  return ntohs(a.sin_port);
}

TEST(NtripClient, Str2StrCasterDeliversEveryFrame) {
  ::signal(SIGPIPE, SIG_IGN);
  const int port = freePort();
  Str2StrCaster caster(port, "rover", "s3cret", "TESTGLO");
  const std::string base = "ntrip://rover:s3cret@127.0.0.1:" + std::to_string(port);
  // Wait until the caster listens (str2str starts within a fraction of a second).
  NtripOptions o;
  o.connectTimeout = 2.0;
  o.readTimeout = 5.0;
  std::unique_ptr<NtripClient> client;
  for (int attempt = 0; attempt < 50 && !client; ++attempt) {
    auto c = std::make_unique<NtripClient>(NtripUrl::parse(base + "/TESTGLO"), o);
    try {
      c->connect();
      client = std::move(c);
    } catch (const NtripError& e) {
      ASSERT_EQ(e.kind(), Kind::ConnectionRefused) << e.what();
      ASSERT_TRUE(caster.running()) << "str2str exited; is RTKLIB (Debian package rtklib) installed?";
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
  ASSERT_TRUE(client) << "str2str caster did not come up on port " << port;
  EXPECT_EQ(client->statusLine(), "ICY 200 OK");

  // Wrong password and wrong mountpoint give clear errors (while the good client stays connected).
  {
    NtripClient bad(NtripUrl::parse("ntrip://rover:wrong@127.0.0.1:" + std::to_string(port) + "/TESTGLO"), o);
    const auto [kind, msg] = errorOf([&] { bad.connect(); });
    EXPECT_EQ(kind, Kind::Unauthorized) << msg;
    std::cerr << "wrong password: " << msg << "\n";
  }
  {
    NtripClient bad(NtripUrl::parse(base + "/NOSUCH"), o);
    const auto [kind, msg] = errorOf([&] { bad.connect(); });
    EXPECT_EQ(kind, Kind::MountpointNotFound) << msg;
    EXPECT_NE(msg.find("TESTGLO"), std::string::npos) << "the error lists the caster's mountpoints: " << msg;
    std::cerr << "wrong mountpoint: " << msg << "\n";
  }
  {
    NtripOptions v1 = o;
    v1.version = 1;
    NtripClient bad(NtripUrl::parse("ntrip://127.0.0.1:" + std::to_string(port) + "/TESTGLO"), v1);
    EXPECT_EQ(errorOf([&] { bad.connect(); }).first, Kind::Unauthorized);
  }

  // Serve the log and check that every frame arrives and decodes.
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const auto data = readBytes(dataDir() / "rtcm/rtklib_testglo.rtcm3");
  const auto expected = testing::independentScan(data);
  caster.write(data);
  DecoderOptions dopt;
  CalendarTime c{2009, 12, 18, 12, 0, 0.0};
  dopt.referenceTime = GpsTime::fromCalendar(c);
  Decoder dec(dopt);
  std::vector<std::uint8_t> buf, all;
  std::int64_t epochs = 0;
  while (dec.stats().framing.frames < expected.frames) {
    buf.clear();
    ASSERT_GT(client->read(buf), 0u);
    all.insert(all.end(), buf.begin(), buf.end());
    dec.feed(buf);
    while (auto item = dec.poll()) epochs += std::holds_alternative<ObsEpoch>(*item);
  }
  dec.finish();
  while (auto item = dec.poll()) epochs += std::holds_alternative<ObsEpoch>(*item);
  EXPECT_EQ(all, data);
  EXPECT_EQ(dec.stats().messages, expected.types);
  EXPECT_EQ(dec.stats().malformed, 0);
  EXPECT_EQ(dec.stats().framing.crcFailures, 0);
  EXPECT_EQ(epochs, 186);
  std::cerr << "str2str caster: " << all.size() << " bytes, " << dec.stats().framing.frames << " frames, " << epochs
            << " epochs\n";
}

}  // namespace
}  // namespace gvins::rtcm
