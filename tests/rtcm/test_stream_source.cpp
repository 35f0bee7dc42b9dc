// Stream paths and sources (stream_url.hpp, stream_source.hpp) against local endpoints: a file,
// a TCP server and a TCP client thread in the test, a pseudo-terminal for the serial path and a
// scripted NTRIP caster. The bytes received must be exactly those sent; drops must be counted
// as gaps and reconnected.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "local_tcp.hpp"
#include "gvins/rtcm/stream_source.hpp"

using namespace gvins::rtcm;
using namespace gvins::testing;
using namespace std::chrono_literals;

namespace {

std::string readAll(StreamSource& s, std::size_t want, double limit = 10.0) {
  std::vector<std::uint8_t> b;
  const auto t0 = std::chrono::steady_clock::now();
  while (b.size() < want && std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() < limit) {
    if (s.read(b, 0.2) == StreamSource::Status::End) break;
  }
  return std::string(b.begin(), b.end());
}

void sendAll(int fd, const std::string& s) { ASSERT_EQ(::send(fd, s.data(), s.size(), MSG_NOSIGNAL), static_cast<ssize_t>(s.size())); }

}  // namespace

TEST(StreamUrl, ParsesEveryKind) {
  auto u = StreamUrl::parse("file://logs/rover.ubx");
  EXPECT_EQ(u.type, StreamType::File);
  EXPECT_EQ(u.path, "logs/rover.ubx");
  EXPECT_EQ(StreamUrl::parse("rover.ubx").type, StreamType::File);
  EXPECT_EQ(StreamUrl::parse("-").type, StreamType::Stdin);
  u = StreamUrl::parse("tcpcli://192.168.1.5:5000");
  EXPECT_EQ(u.type, StreamType::TcpClient);
  EXPECT_EQ(u.host, "192.168.1.5");
  EXPECT_EQ(u.port, 5000);
  u = StreamUrl::parse("tcpcli://[::1]:5001");
  EXPECT_EQ(u.host, "::1");
  EXPECT_EQ(u.port, 5001);
  u = StreamUrl::parse("tcpsvr://:2102");
  EXPECT_EQ(u.type, StreamType::TcpServer);
  EXPECT_EQ(u.host, "");
  EXPECT_EQ(u.port, 2102);
  u = StreamUrl::parse("serial://ttyUSB0:115200");
  EXPECT_EQ(u.type, StreamType::Serial);
  EXPECT_EQ(u.path, "/dev/ttyUSB0");
  EXPECT_EQ(u.baud, 115200);
  EXPECT_EQ(StreamUrl::parse("serial:///dev/pts/7:9600:8N1").path, "/dev/pts/7");
  u = StreamUrl::parse("ntrip://me:p%40ss@caster.example:2102/MOUNT1");
  EXPECT_EQ(u.type, StreamType::Ntrip);
  EXPECT_EQ(u.ntrip.user, "me");
  EXPECT_EQ(u.ntrip.password, "p@ss");
  EXPECT_EQ(u.ntrip.port, 2102);
  EXPECT_EQ(u.ntrip.mountpoint, "MOUNT1");
  EXPECT_EQ(u.display().find("p@ss"), std::string::npos);
  EXPECT_EQ(StreamUrl::parse("ntripcli://caster.example/M").ntrip.port, 2101);
}

TEST(StreamUrl, MalformedPathsNameTheProblem) {
  const std::pair<const char*, const char*> bad[] = {
      {"", "empty"},
      {"tcpcli://host", "no ':PORT'"},
      {"tcpcli://:5000", "no host"},
      {"tcpcli://h:99999", "port '99999'"},
      {"tcpcli://h:12x", "port '12x'"},
      {"tcpcli://h:0", "port '0'"},
      {"tcpcli://[::1:5000", "unterminated"},
      {"serial://ttyUSB0", "no ':BAUD'"},
      {"serial://ttyUSB0:1234", "baud rate '1234'"},
      {"serial://ttyUSB0:9600:7E1", "framing '7E1'"},
      {"serial://:9600", "no serial device"},
      {"ntrip://caster/", "no mountpoint"},
      {"udp://h:1", "unknown stream type 'udp'"},
      {"file://", "no file name"},
      {"file://a.ubx::x10", "not supported"},
  };
  for (const auto& [path, what] : bad) {
    try {
      StreamUrl::parse(path);
      ADD_FAILURE() << path << " parsed";
    } catch (const StreamError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(std::string("'") + path + "'"), std::string::npos) << m;
      EXPECT_NE(m.find(what), std::string::npos) << m;
    }
  }
}

TEST(StreamSource, FileGivesItsBytesThenEnd) {
  const auto path = std::filesystem::temp_directory_path() / ("gvins_stream_" + std::to_string(::getpid()) + ".bin");
  std::string content;
  for (int i = 0; i < 100000; ++i) content += static_cast<char>(i * 7);
  std::ofstream(path, std::ios::binary) << content;
  auto s = StreamSource::open(StreamUrl::parse("file://" + path.string()));
  EXPECT_EQ(readAll(*s, content.size() + 1), content);
  std::vector<std::uint8_t> b;
  EXPECT_EQ(s->read(b, 0.1), StreamSource::Status::End);
  EXPECT_EQ(s->counters().bytes, static_cast<std::int64_t>(content.size()));
  std::filesystem::remove(path);
  EXPECT_THROW(StreamSource::open(StreamUrl::parse(path.string())), StreamError);
}

TEST(StreamSource, TcpClientReconnectsAndCountsTheGap) {
  int port = 0;
  const int lfd = listenLocal(port);
  std::thread server([lfd] {
    int c = acceptWithin(lfd, 5000);
    if (c < 0) return;
    sendAll(c, "first part;");
    std::this_thread::sleep_for(50ms);
    ::close(c);  // the drop
    std::this_thread::sleep_for(300ms);
    c = acceptWithin(lfd, 5000);
    if (c < 0) return;
    sendAll(c, "second part");
    std::this_thread::sleep_for(300ms);
    ::close(c);
  });
  StreamOptions o;
  o.retryInitial = 0.05;
  o.maxOutage = 1.0;
  auto s = StreamSource::open(StreamUrl::parse("tcpcli://127.0.0.1:" + std::to_string(port)), o);
  EXPECT_EQ(readAll(*s, 22), "first part;second part");
  server.join();
  ::close(lfd);
  // The second close and the closed listener: the source gives up after maxOutage.
  std::vector<std::uint8_t> b;
  const auto t0 = std::chrono::steady_clock::now();
  while (s->read(b, 0.2) != StreamSource::Status::End) ASSERT_LT(std::chrono::steady_clock::now() - t0, 10s);
  EXPECT_EQ(s->counters().connects, 2);
  EXPECT_EQ(s->counters().drops, 2);
  EXPECT_GT(s->counters().gapSeconds, 0.25);
  EXPECT_LT(s->counters().gapSeconds, 2.0);
  EXPECT_GT(s->counters().failedAttempts, 0);
  bool reported = false;
  for (const auto& e : s->takeEvents()) reported |= e.find("data again") != std::string::npos;
  EXPECT_TRUE(reported);
}

TEST(StreamSource, TcpServerAcceptsOneClientAfterAnother) {
  StreamOptions o;
  o.maxOutage = 2.0;
  auto s = StreamSource::open(StreamUrl::parse("tcpsvr://127.0.0.1:0"), o);
  const int port = s->boundPort();
  ASSERT_GT(port, 0);
  std::thread client([port] {
    int c = connectLocal(port);
    sendAll(c, "abc");
    std::this_thread::sleep_for(100ms);
    ::close(c);
    c = connectLocal(port);
    sendAll(c, "def");
    std::this_thread::sleep_for(100ms);
    ::close(c);
  });
  EXPECT_EQ(readAll(*s, 6), "abcdef");
  client.join();
  EXPECT_EQ(s->counters().connects, 2);
  EXPECT_GE(s->counters().drops, 1);
}

TEST(StreamSource, SerialThroughAPseudoTerminal) {
  const int master = ::posix_openpt(O_RDWR | O_NOCTTY);
  ASSERT_GE(master, 0);
  ASSERT_EQ(::grantpt(master), 0);
  ASSERT_EQ(::unlockpt(master), 0);
  const std::string slave = ::ptsname(master);
  auto s = StreamSource::open(StreamUrl::parse("serial://" + slave + ":115200"));
  std::vector<std::uint8_t> b;
  EXPECT_EQ(s->read(b, 0.2), StreamSource::Status::Timeout);  // opens the device, nothing yet
  // Raw mode: every byte value passes unchanged (no CR/LF translation, no XON/XOFF).
  std::string bytes;
  for (int i = 0; i < 256; ++i) bytes += static_cast<char>(i);
  ASSERT_EQ(::write(master, bytes.data(), bytes.size()), 256);
  EXPECT_EQ(readAll(*s, 256), bytes);
  ::close(master);
  // Not a terminal: a clear error, retried.
  auto f = StreamSource::open(StreamUrl::parse("serial:///dev/null:9600"), [] {
    StreamOptions so;
    so.maxOutage = 0.3;
    return so;
  }());
  while (f->read(b, 0.2) != StreamSource::Status::End) {
  }
  const auto ev = f->takeEvents();
  ASSERT_FALSE(ev.empty());
  EXPECT_NE(ev.front().find("not a serial port"), std::string::npos) << ev.front();
}

TEST(StreamSource, NtripSendsGgaAndDelivers) {
  int port = 0;
  const int lfd = listenLocal(port);
  std::string request, later;
  std::thread caster([lfd, &request, &later] {
    const int c = acceptWithin(lfd, 5000);
    if (c < 0) return;
    char buf[4096];
    while (request.find("\r\n\r\n") == std::string::npos) {
      const ssize_t n = ::recv(c, buf, sizeof buf, 0);
      if (n <= 0) break;
      request.append(buf, static_cast<std::size_t>(n));
    }
    sendAll(c, "ICY 200 OK\r\n\r\n");
    for (int i = 0; i < 6; ++i) {
      sendAll(c, "data" + std::to_string(i));
      std::this_thread::sleep_for(60ms);
    }
    pollfd p{c, POLLIN, 0};
    if (::poll(&p, 1, 1000) > 0) {
      const ssize_t n = ::recv(c, buf, sizeof buf, 0);
      if (n > 0) later.assign(buf, static_cast<std::size_t>(n));
    }
    ::close(c);
  });
  StreamOptions o;
  o.gga = [] { return std::string("$GPGGA,TEST*00\r\n"); };
  o.ggaInterval = 0.1;
  o.maxOutage = 0.5;
  auto s = StreamSource::open(StreamUrl::parse("ntrip://u:p@127.0.0.1:" + std::to_string(port) + "/MNT"), o);
  EXPECT_EQ(readAll(*s, 30), "data0data1data2data3data4data5");
  caster.join();
  ::close(lfd);
  EXPECT_NE(request.find("GET /MNT"), std::string::npos);
  EXPECT_NE(request.find("Ntrip-GGA: $GPGGA,TEST*00\r\n"), std::string::npos) << request;
  // Sent again every ggaInterval (0.1 s) while the stream ran (0.36 s).
  ASSERT_GE(later.size(), 2 * 16u);
  EXPECT_EQ(later.size() % 16, 0u);
  for (std::size_t i = 0; i < later.size(); i += 16) EXPECT_EQ(later.substr(i, 16), "$GPGGA,TEST*00\r\n");
}
