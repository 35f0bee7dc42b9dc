// Live gvins-rtk against RTKLIB's str2str (2.4.3): the walk UBX log (tests/data/ubx/gnss_1730.ubx,
// 4 Hz) is served as the rover over TCP by `str2str -out tcpsvr://`, its RTCM 3 MSM conversion by
// str2str as the base through str2str's NTRIP caster (`-out ntripc://`); the test writes both
// into the str2str processes at twenty times the recording's rate. There is no published base for
// this log, so the base is the rover's own data (zero baseline). Half-way the rover server is
// killed and restarted: gvins-rtk must reconnect, report the gap and still give, epoch by epoch,
// exactly the rows of post-processing the same files. Its NMEA goes to a TCP client through the
// live tool's TCP server output.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>

#include "gvins/gnss/pos_reader.hpp"
#include "live_loopback.hpp"

using namespace gvins;
using namespace gvins::livetest;
using namespace std::chrono_literals;

namespace {

const std::string kData = GVINS_TEST_DATA;
const std::string kRtk = std::string(GVINS_BIN_DIR) + "/gvins-rtk";
const std::string kBaseLlh = "40.0966916,-105.1471665,1601.435";

std::string tmp(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("gvins_rtk_live_" + std::to_string(::getpid()) + "_" + name)).string();
}

std::vector<std::string> rows(const std::string& path) {
  std::vector<std::string> r;
  std::ifstream f(path);
  for (std::string l; std::getline(f, l);) {
    if (!l.empty() && l[0] != '%') r.push_back(l);
  }
  return r;
}

/// Waits until `file` contains `text` `count` times; false after `limit`.
bool waitFor(const std::string& file, const std::string& text, int count, std::chrono::milliseconds limit) {
  const auto t0 = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - t0 < limit) {
    const std::string s = readText(file);
    int n = 0;
    for (std::size_t p = s.find(text); p != std::string::npos; p = s.find(text, p + 1)) ++n;
    if (n >= count) return true;
    std::this_thread::sleep_for(20ms);
  }
  return false;
}

}  // namespace

TEST(RtkLive, Str2StrLoopbackEqualsPostProcessingAndSurvivesADrop) {
  if (std::system("command -v str2str >/dev/null 2>&1") != 0) GTEST_SKIP() << "str2str (RTKLIB) is not installed";
  ::signal(SIGPIPE, SIG_IGN);
  const std::string rover = kData + "/ubx/gnss_1730.ubx";
  const std::string base = tmp("base.rtcm3"), post = tmp("post.pos"), live = tmp("live.pos"), nmea = tmp("live.nmea");
  const std::string err = tmp("rtk.err"), e1 = tmp("s1.err"), e2 = tmp("s2.err"), e3 = tmp("s3.err"), e0 = tmp("conv.err");
  // The base: str2str's RTCM 3 conversion of the log (MSM7 of GPS, GLONASS, Galileo, BeiDou, 1005).
  {
    Child conv({"str2str", "-in", "file://" + rover + "#ubx", "-out", "file://" + base + "#rtcm3", "-msg",
                "1077,1087,1097,1127,1005(1)", "-p", "40.0966916", "-105.1471665", "1601.435"},
               e0, false);
    // str2str keeps running at the end of its input: stop it once the output stops growing.
    std::uintmax_t size = 0;
    for (int stable = 0, i = 0; stable < 10 && i < 600; ++i) {
      std::this_thread::sleep_for(100ms);
      std::error_code ec;
      const auto now = std::filesystem::file_size(base, ec);
      stable = !ec && now > 0 && now == size ? stable + 1 : 0;
      size = ec ? 0 : now;
    }
    conv.stop();
    ASSERT_GT(size, 100000u) << readText(e0);
  }
  ASSERT_EQ(std::system((kRtk + " -q --base-llh " + kBaseLlh + " -o " + post + " " + rover + " " + base + " 2>/dev/null").c_str()), 0);
  const auto roverEpochs = ubxEpochs(readBytes(rover));
  const auto baseEpochs = rtcmEpochs(readBytes(base));
  ASSERT_EQ(roverEpochs.size(), 536u);
  ASSERT_EQ(baseEpochs.size(), roverEpochs.size());

  const int roverPort = freePort(), casterPort = freePort();
  const std::string roverOut = "tcpsvr://:" + std::to_string(roverPort);
  auto roverServer = std::make_unique<Child>(std::vector<std::string>{"str2str", "-out", roverOut}, e1, true);
  Child caster({"str2str", "-out", "ntripc://u:p@:" + std::to_string(casterPort) + "/WALK"}, e2, true);
  std::this_thread::sleep_for(500ms);
  Child rtk({kRtk, "--base-llh", kBaseLlh, "--rover-stream", "tcpcli://127.0.0.1:" + std::to_string(roverPort), "--base-stream",
             "ntrip://u:p@127.0.0.1:" + std::to_string(casterPort) + "/WALK", "--base-wait", "3", "--max-outage", "2", "-o", live,
             "--nmea", "tcpsvr://127.0.0.1:0"},
            err, false);
  // NMEA served on a TCP port (0: any free one, printed): a client connected before the first row
  // must receive every sentence.
  ASSERT_TRUE(waitFor(err, "NMEA served on TCP port ", 1, 10s)) << readText(err);
  const std::string started = readText(err);
  const int nmeaPort = std::stoi(started.substr(started.find("NMEA served on TCP port ") + 24));
  TcpCollector nmeaClient(nmeaPort);
  ASSERT_TRUE(nmeaClient.connected());
  ASSERT_TRUE(waitFor(err, ": connected", 2, 10s)) << readText(err);
  std::this_thread::sleep_for(300ms);  // str2str notices its clients

  // Twenty times the recording's rate (4 Hz): an epoch every 12.5 ms, base first.
  const auto t0 = std::chrono::steady_clock::now();
  const std::size_t half = roverEpochs.size() / 2;
  auto tk = t0;
  for (std::size_t k = 0; k < roverEpochs.size(); ++k) {
    if (k == half) {
      // Kill the rover server mid-stream and start it again on the same port. First the base
      // epoch after the last rover epoch sent (so that epoch is solved as post-processing pairs
      // it), and time for str2str to pass the rover bytes on and for the row to be written: on a
      // loaded machine a server killed at once can take the last epoch with it.
      ASSERT_TRUE(caster.write(baseEpochs[k]));
      for (std::size_t n = 0, stable = 0, i = 0; stable < 10 && i < 100; ++i) {
        std::this_thread::sleep_for(100ms);
        const std::size_t now = rows(live).size();
        stable = now == n ? stable + 1 : 0;
        n = now;
      }
      roverServer->stop();
      std::this_thread::sleep_for(500ms);
      roverServer = std::make_unique<Child>(std::vector<std::string>{"str2str", "-out", roverOut}, e3, true);
      ASSERT_TRUE(waitFor(err, "reconnected", 1, 15s)) << readText(err);
      std::this_thread::sleep_for(300ms);
      tk = std::chrono::steady_clock::now();
    }
    if (k != half) ASSERT_TRUE(caster.write(baseEpochs[k]));
    ASSERT_TRUE(roverServer->write(roverEpochs[k]));
    tk += 12500us;
    std::this_thread::sleep_until(tk);
  }
  std::this_thread::sleep_for(1s);
  roverServer->stop();
  caster.stop();
  const int rc = rtk.wait();
  const std::string log = readText(err);
  std::cerr << log;
  EXPECT_EQ(rc, 0) << log;

  // Epoch by epoch the rows of post-processing.
  const auto a = rows(post), b = rows(live);
  ASSERT_GT(a.size(), 400u);
  EXPECT_EQ(b.size(), a.size());
  std::size_t same = 0;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
    EXPECT_EQ(b[i], a[i]) << "row " << i;
    same += a[i] == b[i];
  }
  EXPECT_EQ(same, a.size());
  // The drop reported: the rover reconnected, its gaps counted in the summary.
  EXPECT_NE(log.find("reconnected"), std::string::npos);
  EXPECT_NE(log.find("data again"), std::string::npos);
  EXPECT_NE(log.find("2 connections"), std::string::npos) << log;
  // NMEA over TCP: a GGA and an RMC per row, all received by the client connected at the start.
  {
    std::ofstream(nmea, std::ios::binary) << nmeaClient.finish();
  }
  EXPECT_EQ(rows(nmea).size(), 2 * a.size());
  EXPECT_NE(log.find("NMEA      output       tcpsvr://127.0.0.1:0"), std::string::npos) << log;
  for (const auto& f : {base, post, live, nmea, err, e0, e1, e2, e3}) std::filesystem::remove(f);
}

TEST(RtkLive, DamagedAndHostileStreamsAreSkippedOrRefused) {
  // The walk log with garbage in front, every 50th kB damaged (a byte flipped) and cut short
  // mid-frame, as a file stream for rover and base: no crash or hang, malformed frames counted,
  // solutions still written. A stream of random bytes is refused with a clear error.
  auto log = readBytes(kData + "/ubx/gnss_1730.ubx");
  std::vector<std::uint8_t> bad(5000);
  for (std::size_t i = 0; i < bad.size(); ++i) bad[i] = static_cast<std::uint8_t>((i * 2654435761u) >> 13);
  for (std::size_t i = 25000; i < log.size(); i += 50000) log[i] ^= 0x5A;
  log.resize(log.size() - 700);
  log.insert(log.begin(), bad.begin(), bad.end());
  const std::string damaged = tmp("damaged.ubx"), noise = tmp("noise.bin"), out = tmp("damaged.pos"), err = tmp("damaged.err");
  std::ofstream(damaged, std::ios::binary).write(reinterpret_cast<const char*>(log.data()), static_cast<std::streamsize>(log.size()));
  std::ofstream(noise, std::ios::binary).write(reinterpret_cast<const char*>(bad.data()), static_cast<std::streamsize>(bad.size()));
  const std::string common = kRtk + " --base-llh " + kBaseLlh + " --base-wait 5 -o " + out + " ";
  int rc = std::system((common + "--rover-stream file://" + damaged + " --base-stream file://" + damaged + " 2>" + err).c_str());
  std::string text = readText(err);
  EXPECT_EQ(WEXITSTATUS(rc), 0) << text;
  EXPECT_NE(text.find("malformed frames/epochs skipped"), std::string::npos) << text;
  EXPECT_GT(rows(out).size(), 300u);
  rc = std::system((common + "--rover-stream " + noise + " --base-stream file://" + damaged + " 2>" + err).c_str());
  text = readText(err);
  EXPECT_EQ(WEXITSTATUS(rc), 1) << text;
  EXPECT_NE(text.find("neither a u-blox UBX nor an RTCM 3 stream"), std::string::npos) << text;
  rc = std::system((common + "--rover-stream tcpcli://nowhere --base-stream file://" + damaged + " 2>" + err).c_str());
  text = readText(err);
  EXPECT_EQ(WEXITSTATUS(rc), 2) << text;
  EXPECT_NE(text.find("stream path 'tcpcli://nowhere': no ':PORT'"), std::string::npos) << text;
  for (const auto& f : {damaged, noise, out, err}) std::filesystem::remove(f);
}
