// Latency of the live mode of gvins-rtk: the walk UBX log (tests/data/ubx/gnss_1730.ubx, 4 Hz)
// served as the rover over TCP at `speed` times its recording rate (one write per RXM-RAWX
// epoch), the same log as base from a file stream (always ahead, so no epoch waits for the base;
// zero baseline). Prints the median, 99th percentile and maximum of the per-epoch latency that
// gvins-rtk logs (--latency-log: wall time from the arrival of the epoch's last byte to its
// solution written and flushed) and gvins-rtk's summary.
//
//   bench_rtk_live [speed=4] [gvins-rtk path (default ../bin/gvins-rtk next to this program)]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "../../tests/gnss/live_loopback.hpp"

using namespace gvins::livetest;

int main(int argc, char** argv) {
  const double speed = argc > 1 ? std::atof(argv[1]) : 4.0;
  const std::string rtk = argc > 2 ? argv[2] : (std::filesystem::path(argv[0]).parent_path() / "../bin/gvins-rtk").string();
  if (!(speed > 0.0 && speed <= 1000.0)) {
    std::fprintf(stderr, "bench_rtk_live: speed must be in (0, 1000]\n");
    return 2;
  }
  ::signal(SIGPIPE, SIG_IGN);
  const std::string log = std::string(GVINS_TEST_DATA) + "/ubx/gnss_1730.ubx";
  const auto epochs = ubxEpochs(readBytes(log));
  const auto tmp = std::filesystem::temp_directory_path();
  const std::string pid = std::to_string(::getpid());
  const std::string lat = (tmp / ("bench_rtk_live_" + pid + ".csv")).string(), err = (tmp / ("bench_rtk_live_" + pid + ".err")).string();

  // The rover server: a listening socket the live gvins-rtk connects to.
  const int lfd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);  // not inherited by gvins-rtk
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(lfd, reinterpret_cast<sockaddr*>(&a), sizeof a);
  ::listen(lfd, 1);
  socklen_t len = sizeof a;
  ::getsockname(lfd, reinterpret_cast<sockaddr*>(&a), &len);
  const int port = ntohs(a.sin_port);
  Child proc({rtk, "-q", "--base-llh", "40.0966916,-105.1471665,1601.435", "--rover-stream", "tcpcli://127.0.0.1:" + std::to_string(port),
              "--base-stream", "file://" + log, "--max-outage", "0.5", "-o", "/dev/null", "--latency-log", lat},
             err, false);
  const int c = ::accept4(lfd, nullptr, nullptr, SOCK_CLOEXEC);
  std::fprintf(stderr, "bench_rtk_live: %zu epochs at %.1f x 4 Hz\n", epochs.size(), speed);
  const auto step = std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(0.25 / speed));
  auto t = std::chrono::steady_clock::now();
  for (const auto& e : epochs) {
    std::size_t sent = 0;
    while (sent < e.size()) {
      const ssize_t n = ::send(c, e.data() + sent, e.size() - sent, MSG_NOSIGNAL);
      if (n <= 0) break;
      sent += static_cast<std::size_t>(n);
    }
    t += step;
    std::this_thread::sleep_until(t);
  }
  ::close(c);
  ::close(lfd);
  const int rc = proc.wait();
  std::vector<double> ms;
  std::istringstream in(readText(lat));
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string x; std::getline(ss, x, ',');) f.push_back(x);
    if (f.size() >= 4) ms.push_back(std::atof(f[3].c_str()));
  }
  std::fputs(readText(err).c_str(), stderr);
  std::filesystem::remove(lat);
  std::filesystem::remove(err);
  if (ms.empty() || rc != 0) {
    std::fprintf(stderr, "bench_rtk_live: no solutions (gvins-rtk exit %d)\n", rc);
    return 1;
  }
  std::sort(ms.begin(), ms.end());
  auto q = [&](double p) { return ms[std::min(ms.size() - 1, static_cast<std::size_t>(p * static_cast<double>(ms.size() - 1) + 0.5))]; };
  std::printf("live gvins-rtk latency, %zu solutions, rover paced at %.1f x its 4 Hz rate:\n", ms.size(), speed);
  std::printf("  median %.3f ms   p99 %.3f ms   max %.3f ms\n", q(0.5), q(0.99), ms.back());
  return 0;
}
