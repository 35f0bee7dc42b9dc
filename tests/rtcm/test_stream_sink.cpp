// Output streams (stream_sink.hpp) against local TCP peers in the test: what each client
// receives must be exactly the bytes written after it connected; closed and refused peers are
// counted, logged and never stop the writer (no SIGPIPE, no exception).
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include "gvins/rtcm/stream_sink.hpp"

using namespace gvins::rtcm;
using namespace std::chrono_literals;

namespace {

int connectLocal(int port, int receiveBuffer = 0) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (receiveBuffer > 0) ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &receiveBuffer, sizeof receiveBuffer);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  EXPECT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  return fd;
}

/// What arrives on `fd` until `want` bytes or 3 s of silence.
std::string receive(int fd, std::size_t want) {
  std::string got;
  char buf[4096];
  while (got.size() < want) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 3000) <= 0) break;
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n <= 0) break;
    got.append(buf, static_cast<std::size_t>(n));
  }
  return got;
}

int listenLocal(int& port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  const int one = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  EXPECT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  EXPECT_EQ(::listen(fd, 4), 0);
  socklen_t len = sizeof a;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  port = ntohs(a.sin_port);
  return fd;
}

int acceptWithin(int lfd, int ms) {
  pollfd p{lfd, POLLIN, 0};
  return ::poll(&p, 1, ms) > 0 ? ::accept(lfd, nullptr, nullptr) : -1;
}

bool anyEventHas(StreamSink& s, const std::string& what) {
  bool found = false;
  for (const auto& e : s.takeEvents()) found |= e.find(what) != std::string::npos;
  return found;
}

}  // namespace

TEST(StreamSink, TcpServerServesEveryClientFromItsConnectionOn) {
  auto sink = StreamSink::open(StreamUrl::parse("tcpsvr://127.0.0.1:0"));
  const int port = sink->boundPort();
  ASSERT_GT(port, 0);
  sink->write("before anyone;");  // nobody there: discarded
  const int a = connectLocal(port);
  sink->write("row 1\n");
  const int b = connectLocal(port);
  sink->write("row 2\n");
  EXPECT_EQ(receive(a, 12), "row 1\nrow 2\n");
  EXPECT_EQ(receive(b, 6), "row 2\n");
  EXPECT_TRUE(anyEventHas(*sink, "connected"));

  ::close(a);  // a client leaves: it is dropped at the next write, the other one keeps getting rows
  std::this_thread::sleep_for(50ms);
  sink->write("row 3\n");
  sink->write("row 4\n");
  EXPECT_EQ(receive(b, 12), "row 3\nrow 4\n");
  EXPECT_TRUE(anyEventHas(*sink, "dropped: closed by the peer"));
  ::close(b);
  const auto& k = sink->counters();
  EXPECT_EQ(k.bytes, 14 + 4 * 6);
  EXPECT_EQ(k.discarded, 14);
  EXPECT_EQ(k.clients, 2);
  EXPECT_EQ(k.drops, 1);
}

TEST(StreamSink, TcpServerDropsAClientThatDoesNotRead) {
  auto sink = StreamSink::open(StreamUrl::parse("tcpsvr://127.0.0.1:0"));
  const int slow = connectLocal(sink->boundPort());
  const std::string row(64 * 1024, 'x');
  // The kernel buffers take a few MiB at most; then the sink keeps 1 MiB and drops the client
  // instead of blocking the writer or growing without bound.
  for (int i = 0; i < 400 && sink->counters().drops == 0; ++i) sink->write(row);
  EXPECT_EQ(sink->counters().drops, 1);
  EXPECT_TRUE(anyEventHas(*sink, "more than 1 MiB behind"));
  ::close(slow);
}

TEST(StreamSink, DrainHandsTheLastBytesToALateReader) {
  // 600 kB at once is more than the socket buffers take from a client that does not read yet (a
  // small receive window here, the sink's bounded send buffer there): the rest waits in the sink,
  // and drain() at the end of a run must still deliver it.
  auto sink = StreamSink::open(StreamUrl::parse("tcpsvr://127.0.0.1:0"));
  const int c = connectLocal(sink->boundPort(), 4096);
  std::string all;
  for (int i = 0; all.size() < 600000; ++i) all += "row " + std::to_string(i) + "\n";
  sink->write(all);
  std::string got;
  std::thread reader([&] {
    std::this_thread::sleep_for(200ms);
    got = receive(c, all.size());
  });
  sink->drain(5.0);
  reader.join();
  EXPECT_EQ(got.size(), all.size());
  EXPECT_TRUE(got == all);
  EXPECT_EQ(sink->counters().drops, 0);
  ::close(c);
}

TEST(StreamSink, TcpClientReconnectsAfterADrop) {
  int port = 0;
  const int lfd = listenLocal(port);
  auto sink = StreamSink::open(StreamUrl::parse("tcpcli://127.0.0.1:" + std::to_string(port)));
  sink->write("one;");
  int c = acceptWithin(lfd, 3000);
  ASSERT_GE(c, 0);
  EXPECT_EQ(receive(c, 4), "one;");
  ::close(c);  // the server drops the connection
  std::this_thread::sleep_for(50ms);
  sink->write("two;");  // seen as lost: discarded
  EXPECT_TRUE(anyEventHas(*sink, "connection lost"));
  sink->write("three;");  // reconnects at once after a drop
  c = acceptWithin(lfd, 3000);
  ASSERT_GE(c, 0);
  EXPECT_EQ(receive(c, 6), "three;");
  ::close(c);
  ::close(lfd);
  EXPECT_EQ(sink->counters().clients, 2);
  EXPECT_EQ(sink->counters().drops, 1);
  EXPECT_EQ(sink->counters().discarded, 4);
}

TEST(StreamSink, TcpClientWithNobodyListeningDiscardsAndBacksOff) {
  int port = 0;
  ::close(listenLocal(port));  // a port nobody listens on
  auto sink = StreamSink::open(StreamUrl::parse("tcpcli://127.0.0.1:" + std::to_string(port)));
  sink->write("lost;");
  EXPECT_TRUE(anyEventHas(*sink, "cannot connect to 127.0.0.1:" + std::to_string(port)));
  sink->write("lost too;");  // within the back-off: no new attempt, no new message
  EXPECT_TRUE(sink->takeEvents().empty());
  EXPECT_EQ(sink->counters().discarded, 14);
  EXPECT_EQ(sink->counters().clients, 0);
}

TEST(StreamSink, FilesAndOstreamFlushes) {
  const auto path = std::filesystem::temp_directory_path() / ("gvins_sink_" + std::to_string(::getpid()) + ".txt");
  {
    auto sink = StreamSink::open(StreamUrl::parse(path.string()));
    SinkOstream out(*sink);
    out << "a " << 1.5 << '\n' << std::flush;
    EXPECT_EQ(sink->counters().bytes, 6);
    out << "tail";  // handed on when the stream goes
  }
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  EXPECT_EQ(ss.str(), "a 1.5\ntail");
  std::filesystem::remove(path);
}

TEST(StreamSink, InputOnlyPathsAndUncreatableFilesAreErrors) {
  try {
    StreamSink::open(StreamUrl::parse("serial://ttyUSB0:115200"));
    FAIL() << "a serial output was accepted";
  } catch (const StreamError& e) {
    EXPECT_NE(std::string(e.what()).find("input only"), std::string::npos) << e.what();
  }
  try {
    StreamSink::open(StreamUrl::parse("/nonexistent-dir/out.pos"));
    FAIL() << "an output in a missing folder was accepted";
  } catch (const StreamError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/out.pos"), std::string::npos) << e.what();
  }
}
