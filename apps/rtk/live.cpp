#include "live.hpp"

#include <csignal>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <fstream>
#include <iostream>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "gvins/base/parse_error.hpp"
#include "gvins/gnss/accuracy_statistics.hpp"
#include "gvins/gnss/base_reader.hpp"
#include "gvins/gnss/base_station.hpp"
#include "gvins/gnss/nmea_writer.hpp"
#include "gvins/gnss/rtk.hpp"
#include "gvins/rtcm/stream_source.hpp"

namespace gvins::rtklive {

namespace {

using Clock = std::chrono::steady_clock;
std::atomic<bool> gStop{false};
extern "C" void onSignal(int) { gStop = true; }

double ms(Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

/// Bytes of one stream as read by its thread, with the time read() returned them.
struct Chunk {
  int stream = 0;
  std::vector<std::uint8_t> bytes;
  Clock::time_point arrival;
  bool end = false;
  std::vector<std::string> events;
};

class ChunkQueue {
 public:
  void push(Chunk c) {
    {
      std::lock_guard<std::mutex> l(m_);
      q_.push_back(std::move(c));
    }
    cv_.notify_one();
  }
  bool pop(Chunk& c, double timeout) {
    std::unique_lock<std::mutex> l(m_);
    if (!cv_.wait_for(l, std::chrono::duration<double>(timeout), [&] { return !q_.empty(); })) return false;
    c = std::move(q_.front());
    q_.pop_front();
    return true;
  }

 private:
  std::mutex m_;
  std::condition_variable cv_;
  std::deque<Chunk> q_;
};

void readStream(rtcm::StreamSource& src, int id, ChunkQueue& q) {
  std::vector<std::uint8_t> buf;
  for (;;) {
    const auto st = gStop ? rtcm::StreamSource::Status::End : src.read(buf, 0.2);
    Chunk c;
    c.stream = id;
    c.events = src.takeEvents();
    c.arrival = Clock::now();
    if (st == rtcm::StreamSource::Status::Data) c.bytes.swap(buf);
    c.end = st == rtcm::StreamSource::Status::End;
    if (!c.bytes.empty() || c.end || !c.events.empty()) q.push(std::move(c));
    if (c.end) return;
  }
}

/// One input stream: its source, the format detected from its first bytes and the pushed reader.
struct Input {
  std::string role;
  std::unique_ptr<rtcm::StreamSource> source;
  std::unique_ptr<BaseReader> reader;
  std::vector<std::uint8_t> head;  // bytes before the format is known
  bool ended = false, finished = false;
  Clock::time_point lastArrival{};
};

/// Decides the format once enough bytes are there: UBX as soon as a good UBX frame is seen,
/// RTCM after 1 KiB (or at the end) so that a UBX stream starting mid-frame is not taken for RTCM.
std::optional<BaseFormat> decide(const Input& in) {
  const auto f = BaseReader::detectBytes(in.head);
  if (f == BaseFormat::Ubx) return f;
  if (f == BaseFormat::Rtcm && (in.head.size() >= 1024 || in.ended)) return f;
  if (in.head.size() > (1u << 16) || (in.ended && !in.head.empty())) {
    throw ParseError(in.source->name(), 0, "format", "neither a u-blox UBX nor an RTCM 3 stream in its first bytes");
  }
  return std::nullopt;
}

}  // namespace

int runLive(const LiveOptions& opt, const RtkConfig& cfg, const SppConfig& sppCfg, EphemerisStore& nav) {
  struct sigaction sa {};
  sa.sa_handler = onSignal;
  ::sigaction(SIGINT, &sa, nullptr);
  ::sigaction(SIGTERM, &sa, nullptr);
  const auto wall0 = Clock::now();

  // Outputs, written as solutions come (no temporary file: a live run has no "end of success").
  std::ofstream posFile, nmeaFile, latFile;
  std::ostream* posOut = &std::cout;
  if (opt.out != "-") {
    posFile.open(opt.out, std::ios::binary);
    if (!posFile) {
      std::fprintf(stderr, "gvins-rtk: error: cannot create '%s'\n", opt.out.c_str());
      return 1;
    }
    posOut = &posFile;
  }
  std::unique_ptr<NmeaWriter> nmea;
  if (!opt.nmea.empty()) {
    if (opt.nmea != "-") {
      nmeaFile.open(opt.nmea, std::ios::binary);
      if (!nmeaFile) {
        std::fprintf(stderr, "gvins-rtk: error: cannot create '%s'\n", opt.nmea.c_str());
        return 1;
      }
    }
    nmea = std::make_unique<NmeaWriter>(opt.nmea == "-" ? std::cout : nmeaFile);
  }
  if (!opt.latencyLog.empty()) {
    latFile.open(opt.latencyLog, std::ios::binary);
    if (!latFile) {
      std::fprintf(stderr, "gvins-rtk: error: cannot create '%s'\n", opt.latencyLog.c_str());
      return 1;
    }
    latFile << "# gpst_week,tow [s],quality,latency [ms],base age [s]\n";
  }

  // The latest solution as GGA for VRS casters.
  std::mutex ggaMutex;
  std::string gga;
  Input inputs[2];
  inputs[0].role = "rover";
  inputs[1].role = "base";
  try {
    for (int i = 0; i < 2; ++i) {
      rtcm::StreamOptions so;
      so.maxOutage = opt.maxOutage;
      so.gga = [&] {
        std::lock_guard<std::mutex> l(ggaMutex);
        return gga;
      };
      inputs[i].source = rtcm::StreamSource::open(rtcm::StreamUrl::parse(i == 0 ? opt.rover : opt.base), so);
    }
  } catch (const rtcm::StreamError& e) {
    std::fprintf(stderr, "gvins-rtk: error: %s\n", e.what());
    return 2;
  }
  ChunkQueue queue;
  std::thread threads[2];
  for (int i = 0; i < 2; ++i) threads[i] = std::thread(readStream, std::ref(*inputs[i].source), i, std::ref(queue));

  RtkSolver solver(nav, cfg, sppCfg);
  std::optional<Eigen::Vector3d> basePos = opt.baseXyz;
  if (basePos) solver.setBasePosition(*basePos);
  std::unique_ptr<PosWriter> writer;
  PosWriterOptions popt = opt.pos;

  ObsEpoch roverEpoch, baseEpoch;
  bool haveRover = false;
  Clock::time_point roverArrival{};
  std::optional<GpsTime> lastBaseTime;
  long epochs = 0, baseEpochs = 0, fixed = 0, floats = 0, singles = 0, none = 0;
  QuantileHistogram latency, ages;
  double latencyMax = 0.0;
  int exitCode = 0;
  Input& rover = inputs[0];
  Input& base = inputs[1];

  std::optional<GpsTime> firstRoverTime;
  auto openIfKnown = [&](Input& in, const GpsTime& ref) {
    if (in.reader) return;
    if (const auto f = decide(in)) {
      in.reader = BaseReader::openPushed(*f, in.source->name(), ref, &nav, !opt.strict);
      in.reader->feed(in.head);
      in.head.clear();
      in.head.shrink_to_fit();
      if (in.ended) {
        in.reader->finish();
        in.finished = true;
      }
      if (!opt.quiet) {
        std::fprintf(stderr, "gvins-rtk: %s stream %s: %s\n", in.role.c_str(), in.source->name().c_str(),
                     *f == BaseFormat::Ubx ? "u-blox UBX" : "RTCM 3");
      }
    }
  };
  auto setBasePosition = [&] {
    if (!basePos && base.reader) {
      if (auto p = base.reader->antennaPosition()) {
        solver.setBasePosition(*p);
        basePos = p;
      }
    }
  };

  try {
    for (;;) {
      if (gStop) break;
      // 1. The next rover epoch, decoded only when the previous one is solved (as the
      //    post-processing reads it, so that ephemerides after it are not used before it).
      if (!haveRover && rover.reader) {
        // The epoch was completed by the last chunk fed (chunk granularity of the latency).
        haveRover = rover.reader->next(roverEpoch);
        if (haveRover) {
          roverArrival = rover.lastArrival;
          ++epochs;
        }
      }
      if (haveRover && !firstRoverTime) {
        firstRoverTime = roverEpoch.time;
        openIfKnown(base, *firstRoverTime);
      }
      if (!haveRover && rover.ended) break;
      // 2. Base epochs up to the rover time and the first one after it, as post-processing feeds them.
      if (haveRover && base.reader) {
        const GpsTime t = roverEpoch.time;
        while (!(lastBaseTime && *lastBaseTime - t > BaseStation::kSyncTolerance)) {
          if (!base.reader->next(baseEpoch)) break;
          ++baseEpochs;
          setBasePosition();
          solver.setBaseGlonassChannels(base.reader->glonassChannels());
          solver.setPhaseAlignment(rover.reader->phaseAlignment(), base.reader->phaseAlignment());
          solver.addBaseEpoch(baseEpoch);
          lastBaseTime = baseEpoch.time;
        }
        setBasePosition();
      }
      // 3. Solve when the base is there or may not be waited for any longer.
      if (haveRover) {
        const bool baseAfter = lastBaseTime && *lastBaseTime - roverEpoch.time > BaseStation::kSyncTolerance;
        const bool ready = opt.baseWait <= 0.0 || base.ended || baseAfter ||
                           std::chrono::duration<double>(Clock::now() - roverArrival).count() > opt.baseWait;
        if (ready) {
          if (rover.reader->format() != BaseFormat::Rinex) solver.setRoverGlonassChannels(rover.reader->glonassChannels());
          const RtkSolution sol = solver.process(roverEpoch);
          haveRover = false;
          switch (sol.quality) {
            case SolutionQuality::Fix: ++fixed; break;
            case SolutionQuality::Float: ++floats; break;
            case SolutionQuality::Single: ++singles; break;
            default: ++none; break;
          }
          if (sol.valid()) {
            const PositionSolution ps = sol.toPositionSolution();
            if (!writer) {
              if (basePos) {
                char b[160];
                std::snprintf(b, sizeof b, "%.4f %.4f %.4f", (*basePos)[0], (*basePos)[1], (*basePos)[2]);
                popt.headerFields.emplace_back("ref pos", b);
              }
              writer = std::make_unique<PosWriter>(*posOut, popt);
            }
            writer->write(ps);
            posOut->flush();
            if (nmea) nmea->write(ps);
            {
              std::lock_guard<std::mutex> l(ggaMutex);
              gga = nmeaGga(ps);
            }
            const double lat = ms(Clock::now() - roverArrival);
            latency.add(lat);
            latencyMax = std::max(latencyMax, lat);
            if (sol.quality != SolutionQuality::Single) ages.add(sol.age);
            if (latFile.is_open()) {
              char b[160];
              std::snprintf(b, sizeof b, "%d,%.3f,%d,%.3f,%.2f\n", sol.time.week(), sol.time.tow(), static_cast<int>(sol.quality), lat, sol.age);
              latFile << b;
            }
          }
          continue;  // the next epoch may already be decoded
        }
      }
      // 4. More bytes.
      Chunk c;
      if (!queue.pop(c, haveRover ? 0.01 : 0.2)) continue;
      Input& in = inputs[c.stream];
      for (const auto& e : c.events) std::fprintf(stderr, "gvins-rtk: %s\n", e.c_str());
      if (c.end) in.ended = true;
      if (!in.reader) {
        in.head.insert(in.head.end(), c.bytes.begin(), c.bytes.end());
      } else if (!c.bytes.empty()) {
        in.reader->feed(c.bytes);
      }
      if (!c.bytes.empty()) in.lastArrival = c.arrival;
      openIfKnown(rover, GpsTime{});
      // RTCM times of week of the base are resolved near the rover's first epoch: the base
      // waits for it (its bytes are kept meanwhile).
      if (firstRoverTime || rover.ended || base.head.size() > (1u << 22)) openIfKnown(base, firstRoverTime.value_or(GpsTime{}));
      if (in.ended && in.reader && !in.finished) {
        in.reader->finish();
        in.finished = true;
      }
    }
  } catch (const ParseError& e) {
    std::fprintf(stderr, "gvins-rtk: error: %s\n", e.what());
    exitCode = 1;
  }
  const bool signalled = gStop;
  gStop = true;
  for (auto& t : threads) t.join();
  if (!writer) writer = std::make_unique<PosWriter>(*posOut, popt);
  writer->finish();

  // Summary.
  const double wall = std::chrono::duration<double>(Clock::now() - wall0).count();
  std::fprintf(stderr, "gvins-rtk live summary (rover %s, base %s)\n", rover.source->name().c_str(), base.source->name().c_str());
  std::fprintf(stderr, "  rover epochs           %8ld (%s)\n", epochs, rover.reader ? rover.reader->describe().c_str() : "no data");
  std::fprintf(stderr, "  base epochs            %8ld (%s)\n", baseEpochs, base.reader ? base.reader->describe().c_str() : "no data");
  std::fprintf(stderr, "  fixed / float / single / none  %ld / %ld / %ld / %ld\n", fixed, floats, singles, none);
  if (latency.count() > 0) {
    std::fprintf(stderr, "  latency                median %.2f ms  p99 %.2f ms  max %.2f ms (last byte of the epoch to its solution written)\n",
                 latency.quantile(0.5), latency.quantile(0.99), latencyMax);
  }
  if (ages.count() > 0) std::fprintf(stderr, "  base age               median %.2f s  max %.2f s\n", ages.quantile(0.5), ages.quantile(1.0));
  for (const Input& in : inputs) {
    const auto& k = in.source->counters();
    std::fprintf(stderr, "  %-5s stream           %lld bytes, %lld connections, %lld failed attempts, %lld gaps (%.1f s without data)\n",
                 in.role.c_str(), static_cast<long long>(k.bytes), static_cast<long long>(k.connects),
                 static_cast<long long>(k.failedAttempts), static_cast<long long>(k.drops), k.gapSeconds);
    if (in.reader && in.reader->skipped()) {
      std::fprintf(stderr, "  %-5s input            %lld malformed frames/epochs skipped\n", in.role.c_str(),
                   static_cast<long long>(in.reader->skipped()));
    }
  }
  std::fprintf(stderr, "  time                   %8.1f s%s\n", wall, signalled ? " (stopped by a signal)" : "");
  if (epochs == 0 && exitCode == 0) exitCode = 3;
  return exitCode;
}

}  // namespace gvins::rtklive
