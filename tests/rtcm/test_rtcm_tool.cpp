// gvins-rtcm end to end: `info` tables against the independent frame scan on every bundled log,
// `to-rinex` on rtklib_testglo.rtcm3 against RTKLIB's conversion (observation by observation,
// navigation records) with SPP on the result against the 1005 station position, and `ntrip`
// recording from RTKLIB's str2str caster.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <sstream>

#include "gvins/base/rinex_obs_reader.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/gnss/spp.hpp"
#include "independent_frame_scan.hpp"
#include "run_command.hpp"

namespace gvins::rtcm {
namespace {

using testing::dataDir;
using testing::readBytes;

const std::string kTool = std::string(GVINS_BIN_DIR) + "/gvins-rtcm";

/// Stops a child process however a test ends (closing `fd`, its input, first).
struct Reaper {
  pid_t pid;
  int fd;
  ~Reaper() {
    if (fd >= 0) ::close(fd);
    if (pid > 0 && ::waitpid(pid, nullptr, WNOHANG) == 0) {
      ::kill(pid, SIGTERM);
      ::waitpid(pid, nullptr, 0);
    }
  }
};

/// Runs a shell command, returns stdout and the exit status.
std::pair<std::string, int> run(const std::string& cmd) { return gvins::test::runCommand(cmd); }

std::filesystem::path tempDir() {
  const auto d = std::filesystem::temp_directory_path() / ("gvins_rtcm_tool_" + std::to_string(::getpid()));
  std::filesystem::create_directories(d);
  return d;
}

/// The rows "  TYPE  COUNT  description" of an info table.
std::map<int, std::int64_t> tableRows(const std::string& out) {
  std::map<int, std::int64_t> rows;
  std::istringstream ss(out);
  std::string line;
  bool inTable = false;
  while (std::getline(ss, line)) {
    if (line.find("type     count  description") != std::string::npos) {
      inTable = true;
      continue;
    }
    if (!inTable) continue;
    std::istringstream ls(line);
    std::string first;
    ls >> first;
    if (first == "total") break;
    std::int64_t count = 0;
    ls >> count;
    rows[first == "-" ? -1 : std::stoi(first)] = count;
  }
  return rows;
}

TEST(Tool, InfoTableMatchesIndependentCountOnEveryLog) {
  int files = 0;
  for (const auto& path : testing::rtcmFiles()) {
    if (path.parent_path().filename() == "go-gnss_frames") continue;  // single frames: covered by the framer test
    const auto ref = testing::independentScan(readBytes(path));
    const auto [out, status] = run(kTool + " info '" + path.string() + "' --date 2020-01-01 2>/dev/null");
    ASSERT_EQ(status, 0) << path;
    EXPECT_EQ(tableRows(out), ref.types) << path << "\n" << out;
    // CRC failures line.
    EXPECT_NE(out.find("CRC failures   " + std::to_string(ref.badCandidates) + " "), std::string::npos) << out;
    ++files;
  }
  EXPECT_EQ(files, 14);
  // Reading from a pipe gives the same table.
  const auto gmsd = dataDir() / "rtcm/rtklib_GMSD7_20121014.rtcm3";
  const auto [piped, st] = run("cat '" + gmsd.string() + "' | " + kTool + " info - --date 2012-10-13 2>/dev/null");
  ASSERT_EQ(st, 0);
  EXPECT_EQ(tableRows(piped), testing::independentScan(readBytes(gmsd)).types);
  EXPECT_NE(piped.find("2012-10-13 23:59:44.000 - 2012-10-14 00:04:00.000 GPST (257 epochs"), std::string::npos) << piped;
  // Without --date the absolute date comes from the stream when it has one (USCL: 1042/1045/1046).
  const auto [auto_, st2] = run(kTool + " info '" + (dataDir() / "rtcm/pyrtcm_pygpsdata-NTRIP-USCL00CHL0.log").string() + "' 2>/dev/null");
  ASSERT_EQ(st2, 0);
  EXPECT_NE(auto_.find("time span      2024-03-13 16:35:45.000"), std::string::npos) << auto_;
  // Usage errors.
  EXPECT_EQ(run(kTool + " info 2>/dev/null").second, 2);
  EXPECT_EQ(run(kTool + " to-rinex x -o y 2>/dev/null").second, 2);  // no --date
  EXPECT_EQ(run(kTool + " info /no/such/file 2>/dev/null").second, 1);
}

TEST(Tool, ToRinexMatchesRtklibAndSppFindsTheStation) {
  const auto dir = tempDir();
  const std::string prefix = (dir / "testglo").string();
  const auto [out, status] = run(kTool + " to-rinex '" + (dataDir() / "rtcm/rtklib_testglo.rtcm3").string() +
                                 "' --date 2009-12-18 -o '" + prefix + "' 2>&1");
  ASSERT_EQ(status, 0) << out;

  // Observations, epoch by epoch, against RTKLIB's conversion.
  RinexObsReader ours(prefix + ".obs");
  RinexObsReader theirs((dataDir() / "reference/rtklib-2.4.3/rtcm_testglo_convbin.obs").string());
  for (System s : {System::Gps, System::Glonass, System::Sbas}) {
    std::vector<std::string> a, b;
    for (const auto& d : ours.header().types(s)) a.push_back(d.str());
    for (const auto& d : theirs.header().types(s)) b.push_back(d.str());
    EXPECT_EQ(a, b) << systemName(s);
  }
  for (int slot = 1; slot <= 27; ++slot) EXPECT_EQ(ours.header().glonassChannels.get(slot), theirs.header().glonassChannels.get(slot)) << slot;
  ASSERT_TRUE(ours.header().station.approxPosition);
  EXPECT_LT((*ours.header().station.approxPosition - *theirs.header().station.approxPosition).norm(), 1e-4);
  ObsEpoch a, b;
  std::int64_t values = 0;
  double maxC = 0, maxL = 0, maxS = 0;
  int epochs = 0;
  while (theirs.next(b)) {
    ASSERT_TRUE(ours.next(a));
    ASSERT_EQ(a.time, b.time);
    ASSERT_EQ(a.sats.size(), b.sats.size());
    for (const SatObs& sb : b.sats) {
      const SatObs* sa = a.find(sb.sat);
      ASSERT_NE(sa, nullptr) << sb.sat.str();
      ASSERT_EQ(sa->signals.size(), sb.signals.size()) << sb.sat.str();
      for (const SignalObs& gb : sb.signals) {
        const SignalObs* ga = sa->find(gb.code);
        ASSERT_NE(ga, nullptr);
        EXPECT_EQ(ga->present, gb.present) << sb.sat.str() << " " << gb.code.str();
        if (gb.hasCode()) maxC = std::max(maxC, std::abs(ga->pseudorange - gb.pseudorange));
        if (gb.hasPhase()) maxL = std::max(maxL, std::abs(ga->carrierPhase - gb.carrierPhase));
        if (gb.hasSnr()) maxS = std::max(maxS, std::abs(ga->snr - gb.snr));
        if (epochs > 0 && gb.hasPhase()) {
          EXPECT_EQ(ga->lli & 1, gb.lli & 1) << sb.sat.str();
        }
        values += (gb.hasCode() ? 1 : 0) + (gb.hasPhase() ? 1 : 0) + (gb.hasSnr() ? 1 : 0);
      }
    }
    ++epochs;
  }
  EXPECT_FALSE(ours.next(a));
  std::cerr << "to-rinex vs RTKLIB convbin: " << epochs << " epochs, " << values << " values, max |dC| " << maxC
            << " m, |dL| " << maxL << " cycles, |dS| " << maxS << " dB-Hz\n";
  EXPECT_EQ(epochs, 186);
  EXPECT_LE(maxC, 0.0011);  // both files are rounded to 0.001
  EXPECT_LE(maxL, 0.0011);
  EXPECT_LE(maxS, 0.0011);

  // Navigation records against RTKLIB's.
  const NavData navOurs = readRinexNav(prefix + ".nav");
  const NavData navTheirs = readRinexNav((dataDir() / "reference/rtklib-2.4.3/rtcm_testglo_convbin.nav").string());
  EXPECT_EQ(navOurs.kepler.size(), navTheirs.kepler.size());
  EXPECT_EQ(navOurs.glonass.size(), navTheirs.glonass.size());
  for (const KeplerEphemeris& r : navTheirs.kepler) {
    const auto it = std::find_if(navOurs.kepler.begin(), navOurs.kepler.end(),
                                 [&](const KeplerEphemeris& k) { return k.sat == r.sat && k.toe == r.toe; });
    ASSERT_NE(it, navOurs.kepler.end()) << r.sat.str();
    EXPECT_NEAR(it->sqrtA, r.sqrtA, 1e-8);
    EXPECT_NEAR(it->m0, r.m0, 1e-11);
    EXPECT_NEAR(it->af0, r.af0, 1e-15);
    EXPECT_EQ(it->iode, r.iode);
  }

  // SPP with its default configuration on our RINEX files (GPS + GLONASS here; RTCM carries no
  // Klobuchar parameters). For scale: RTKLIB 2.4.3's rnx2rtkp -p 0 -m 15 -sys G,R on its own
  // conversion of the log lands 4.64 m from the 1005 position (mean of the 186 epochs).
  EphemerisStore store;
  store.add(navOurs);
  SppSolver spp(store, SppConfig{});
  RinexObsReader again(prefix + ".obs");
  spp.setGlonassChannels(again.header().glonassChannels);
  const Eigen::Vector3d truth(-3869297.5138, 3436571.3345, 3717369.3757);  // 1005 of the log
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int solved = 0;
  double worst = 0.0;
  while (again.next(a)) {
    const SppSolution s = spp.solve(a);
    if (!s.valid()) continue;
    sum += s.position;
    worst = std::max(worst, (s.position - truth).norm());
    ++solved;
  }
  ASSERT_GT(solved, 180);
  const Eigen::Vector3d mean = sum / solved;
  std::cerr << "SPP on converted testglo: " << solved << " epochs, mean 3D error " << (mean - truth).norm()
            << " m, worst epoch " << worst << " m\n";
  EXPECT_LT((mean - truth).norm(), 5.0);
  EXPECT_LT(worst, 10.0);
  std::filesystem::remove_all(dir);
}

TEST(Tool, NtripRecordsEveryFrameFromStr2Str) {
  ::signal(SIGPIPE, SIG_IGN);
  const auto dir = tempDir();
  const std::string outFile = (dir / "rec.rtcm3").string();
  // Caster: str2str reading its standard input.
  int port = 0;
  {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr);
    socklen_t len = sizeof addr;
    ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
    port = ntohs(addr.sin_port);
    ::close(fd);
  }
  int casterIn[2];
  ASSERT_EQ(::pipe(casterIn), 0);
  const std::string spec = "ntripc://user:pw@:" + std::to_string(port) + "/TG";
  const pid_t caster = ::fork();
  if (caster == 0) {
    ::dup2(casterIn[0], 0);
    ::close(casterIn[1]);
    const int devnull = ::open("/dev/null", O_WRONLY);
    ::dup2(devnull, 2);
    ::execlp("str2str", "str2str", "-out", spec.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ::close(casterIn[0]);
  Reaper casterGuard{caster, casterIn[1]};  // destroyed after the recorder's: caster stops last
  ::usleep(300000);
  // Recorder: gvins-rtcm ntrip, its progress on a pipe we watch.
  int errPipe[2];
  ASSERT_EQ(::pipe(errPipe), 0);
  const std::string url = "ntrip://user:pw@127.0.0.1:" + std::to_string(port) + "/TG";
  const pid_t rec = ::fork();
  if (rec == 0) {
    ::dup2(errPipe[1], 2);
    ::close(errPipe[0]);
    const int devnull = ::open("/dev/null", O_WRONLY);
    ::dup2(devnull, 1);
    ::execl(kTool.c_str(), "gvins-rtcm", "ntrip", url.c_str(), "-o", outFile.c_str(), "--frames", "429",
            "--timeout", "10", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ::close(errPipe[1]);
  std::string err;
  char buf[512];
  Reaper recorder{rec, -1};
  auto answered = [&] {
    const std::size_t p = err.find("caster answered");
    return p != std::string::npos && err.find('\n', p) != std::string::npos;
  };
  while (!answered()) {
    const ssize_t n = ::read(errPipe[0], buf, sizeof buf);
    if (n <= 0) break;
    err.append(buf, static_cast<std::size_t>(n));
  }
  ASSERT_NE(err.find("caster answered 'ICY 200 OK'"), std::string::npos) << err;
  ::usleep(200000);
  const auto data = readBytes(dataDir() / "rtcm/rtklib_testglo.rtcm3");
  std::size_t sent = 0;
  while (sent < data.size()) {
    const ssize_t n = ::write(casterIn[1], data.data() + sent, data.size() - sent);
    ASSERT_GT(n, 0);
    sent += static_cast<std::size_t>(n);
  }
  ssize_t n;
  while ((n = ::read(errPipe[0], buf, sizeof buf)) > 0) err.append(buf, static_cast<std::size_t>(n));
  int status = 0;
  ::waitpid(rec, &status, 0);
  recorder.pid = -1;
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << err;
  // The recording is the served log byte for byte (it ends exactly after frame 429).
  const auto got = readBytes(outFile);
  EXPECT_EQ(got.size(), data.size());
  EXPECT_TRUE(got == data);
  EXPECT_NE(err.find("429 frames"), std::string::npos) << err;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace gvins::rtcm
