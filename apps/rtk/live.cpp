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
#include "gvins/rtcm/stream_sink.hpp"
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

/// One output of the run: its sink and the std::ostream the writers use.
struct Output {
  const char* what = "";
  std::unique_ptr<rtcm::StreamSink> sink;
  std::unique_ptr<rtcm::SinkOstream> stream;
};

/// One live run: streams, reader threads, the solver and the outputs.
class LiveSession {
 public:
  LiveSession(const LiveOptions& opt, const RtkConfig& cfg, const SppConfig& sppCfg, EphemerisStore& nav)
      : opt_(opt), nav_(nav), solver_(nav, cfg, sppCfg), basePos_(opt.baseXyz), popt_(opt.pos) {
    if (basePos_) solver_.setBasePosition(*basePos_);
    in_[0].role = "rover";
    in_[1].role = "base";
  }

  int run() {
    const auto wall0 = Clock::now();
    if (!openOutputs()) return 1;
    if (!openStreams()) return 2;
    std::thread threads[2];
    for (int i = 0; i < 2; ++i) threads[i] = std::thread(readStream, std::ref(*in_[i].source), i, std::ref(queue_));
    int exitCode = 0;
    try {
      loop();
    } catch (const ParseError& e) {
      std::fprintf(stderr, "gvins-rtk: error: %s\n", e.what());
      exitCode = 1;
    }
    const bool signalled = gStop;
    gStop = true;
    for (auto& t : threads) t.join();
    if (!writer_) writer_ = std::make_unique<PosWriter>(*posOut_.stream, popt_);
    writer_->finish();
    posOut_.stream->flush();
    for (Output* o : {&posOut_, &nmeaOut_}) {
      if (o->sink) o->sink->drain(5.0);
    }
    reportOutputEvents();
    summary(std::chrono::duration<double>(Clock::now() - wall0).count(), signalled);
    if (epochs_ == 0 && exitCode == 0) exitCode = 3;
    return exitCode;
  }

 private:
  /// Outputs, written and flushed as solutions come (no temporary file: a live run has no "end of
  /// success"): files, standard output, or TCP server/client streams (stream_sink.hpp).
  bool openSink(const std::string& path, const char* what, Output& o) {
    try {
      o.sink = rtcm::StreamSink::open(rtcm::StreamUrl::parse(path));
    } catch (const rtcm::StreamError& e) {
      std::fprintf(stderr, "gvins-rtk: error: %s output: %s\n", what, e.what());
      return false;
    }
    o.stream = std::make_unique<rtcm::SinkOstream>(*o.sink);
    o.what = what;
    if (o.sink->boundPort() > 0) std::fprintf(stderr, "gvins-rtk: %s served on TCP port %d\n", what, o.sink->boundPort());
    return true;
  }

  bool openOutputs() {
    if (!openSink(opt_.out, "solutions", posOut_)) return false;
    if (!opt_.nmea.empty()) {
      if (!openSink(opt_.nmea, "NMEA", nmeaOut_)) return false;
      nmea_ = std::make_unique<NmeaWriter>(*nmeaOut_.stream);
    }
    if (!opt_.latencyLog.empty()) {
      latFile_.open(opt_.latencyLog, std::ios::binary);
      if (!latFile_) {
        std::fprintf(stderr, "gvins-rtk: error: cannot create '%s'\n", opt_.latencyLog.c_str());
        return false;
      }
      latFile_ << "# gpst_week,tow [s],quality,latency [ms],base age [s]\n";
    }
    return true;
  }

  /// Connection events of the outputs, as they happen.
  void reportOutputEvents() {
    for (Output* o : {&posOut_, &nmeaOut_}) {
      if (!o->sink) continue;
      for (const auto& e : o->sink->takeEvents()) std::fprintf(stderr, "gvins-rtk: %s\n", e.c_str());
    }
  }

  bool openStreams() {
    struct sigaction sa {};
    sa.sa_handler = onSignal;
    ::sigaction(SIGINT, &sa, nullptr);
    ::sigaction(SIGTERM, &sa, nullptr);
    try {
      for (int i = 0; i < 2; ++i) {
        rtcm::StreamOptions so;
        so.maxOutage = opt_.maxOutage;
        so.gga = [this] {  // the latest solution, for VRS casters
          std::lock_guard<std::mutex> l(ggaMutex_);
          return gga_;
        };
        in_[i].source = rtcm::StreamSource::open(rtcm::StreamUrl::parse(i == 0 ? opt_.rover : opt_.base), so);
      }
    } catch (const rtcm::StreamError& e) {
      std::fprintf(stderr, "gvins-rtk: error: %s\n", e.what());
      return false;
    }
    return true;
  }

  void openIfKnown(Input& in, const GpsTime& ref) {
    if (in.reader) return;
    const auto f = decide(in);
    if (!f) return;
    in.reader = BaseReader::openPushed(*f, in.source->name(), ref, &nav_, !opt_.strict);
    in.reader->feed(in.head);
    in.head.clear();
    in.head.shrink_to_fit();
    if (in.ended) {
      in.reader->finish();
      in.finished = true;
    }
    if (!opt_.quiet) {
      std::fprintf(stderr, "gvins-rtk: %s stream %s: %s\n", in.role.c_str(), in.source->name().c_str(),
                   *f == BaseFormat::Ubx ? "u-blox UBX" : "RTCM 3");
    }
  }

  void setBasePosition() {
    if (basePos_ || !in_[1].reader) return;
    if (auto p = in_[1].reader->antennaPosition()) {
      solver_.setBasePosition(*p);
      basePos_ = p;
    }
  }

  /// Base epochs up to the rover time and the first one after it, as post-processing feeds them.
  void feedBase(const GpsTime& t) {
    Input& base = in_[1];
    while (!(lastBaseTime_ && *lastBaseTime_ - t > BaseStation::kSyncTolerance)) {
      if (!base.reader->next(baseEpoch_)) break;
      ++baseEpochs_;
      setBasePosition();
      solver_.setBaseGlonassChannels(base.reader->glonassChannels());
      solver_.setPhaseAlignment(in_[0].reader->phaseAlignment(), base.reader->phaseAlignment());
      solver_.addBaseEpoch(baseEpoch_);
      lastBaseTime_ = baseEpoch_.time;
    }
    setBasePosition();
  }

  void solveAndWrite() {
    if (in_[0].reader->format() != BaseFormat::Rinex) solver_.setRoverGlonassChannels(in_[0].reader->glonassChannels());
    const RtkSolution sol = solver_.process(roverEpoch_);
    switch (sol.quality) {
      case SolutionQuality::Fix: ++fixed_; break;
      case SolutionQuality::Float: ++floats_; break;
      case SolutionQuality::Single: ++singles_; break;
      default: ++none_; break;
    }
    if (!sol.valid()) return;
    const PositionSolution ps = sol.toPositionSolution();
    if (!writer_) {
      if (basePos_) {
        char b[160];
        std::snprintf(b, sizeof b, "%.4f %.4f %.4f", (*basePos_)[0], (*basePos_)[1], (*basePos_)[2]);
        popt_.headerFields.emplace_back("ref pos", b);
      }
      writer_ = std::make_unique<PosWriter>(*posOut_.stream, popt_);
    }
    writer_->write(ps);
    posOut_.stream->flush();
    if (nmea_) {
      nmea_->write(ps, NmeaExtras{sol.hdop, std::nullopt});
      nmeaOut_.stream->flush();
    }
    reportOutputEvents();
    {
      std::lock_guard<std::mutex> l(ggaMutex_);
      gga_ = nmeaGga(ps, NmeaExtras{sol.hdop, std::nullopt});
    }
    const double lat = ms(Clock::now() - roverArrival_);
    latency_.add(lat);
    latencyMax_ = std::max(latencyMax_, lat);
    if (sol.quality != SolutionQuality::Single) ages_.add(sol.age);
    if (latFile_.is_open()) {
      char b[160];
      std::snprintf(b, sizeof b, "%d,%.3f,%d,%.3f,%.2f\n", sol.time.week(), sol.time.tow(), static_cast<int>(sol.quality), lat, sol.age);
      latFile_ << b;
    }
  }

  /// Waits up to `timeout` s for bytes of either stream and feeds them.
  void takeChunk(double timeout) {
    Chunk c;
    if (!queue_.pop(c, timeout)) return;
    Input& in = in_[c.stream];
    for (const auto& e : c.events) std::fprintf(stderr, "gvins-rtk: %s\n", e.c_str());
    if (c.end) in.ended = true;
    if (!in.reader) in.head.insert(in.head.end(), c.bytes.begin(), c.bytes.end());
    else if (!c.bytes.empty()) in.reader->feed(c.bytes);
    if (!c.bytes.empty()) in.lastArrival = c.arrival;
    openIfKnown(in_[0], GpsTime{});
    // RTCM times of week of the base are resolved near the rover's first epoch: the base waits
    // for it (its bytes are kept meanwhile).
    if (firstRoverTime_ || in_[0].ended || in_[1].head.size() > (1u << 22)) openIfKnown(in_[1], firstRoverTime_.value_or(GpsTime{}));
    if (in.ended && in.reader && !in.finished) {
      in.reader->finish();
      in.finished = true;
    }
  }

  void loop() {
    Input& rover = in_[0];
    Input& base = in_[1];
    bool haveRover = false;
    while (!gStop) {
      // The next rover epoch, decoded only when the previous one is solved (as post-processing
      // reads it, so that ephemerides after it are not used before it). It was completed by the
      // last chunk fed (chunk granularity of the latency).
      if (!haveRover && rover.reader && rover.reader->next(roverEpoch_)) {
        haveRover = true;
        roverArrival_ = rover.lastArrival;
        ++epochs_;
      }
      if (haveRover && !firstRoverTime_) {
        firstRoverTime_ = roverEpoch_.time;
        openIfKnown(base, *firstRoverTime_);
      }
      if (!haveRover && rover.ended) break;
      if (haveRover && base.reader) feedBase(roverEpoch_.time);
      // Solve when the base is there or may not be waited for any longer.
      if (haveRover) {
        const bool baseAfter = lastBaseTime_ && *lastBaseTime_ - roverEpoch_.time > BaseStation::kSyncTolerance;
        if (opt_.baseWait <= 0.0 || base.ended || baseAfter ||
            std::chrono::duration<double>(Clock::now() - roverArrival_).count() > opt_.baseWait) {
          solveAndWrite();
          haveRover = false;
          continue;  // the next epoch may already be decoded
        }
      }
      takeChunk(haveRover ? 0.01 : 0.2);
    }
  }

  void summary(double wall, bool signalled) const {
    const Input& rover = in_[0];
    const Input& base = in_[1];
    std::fprintf(stderr, "gvins-rtk live summary (rover %s, base %s)\n", rover.source->name().c_str(), base.source->name().c_str());
    std::fprintf(stderr, "  rover epochs           %8ld (%s)\n", epochs_, rover.reader ? rover.reader->describe().c_str() : "no data");
    std::fprintf(stderr, "  base epochs            %8ld (%s)\n", baseEpochs_, base.reader ? base.reader->describe().c_str() : "no data");
    std::fprintf(stderr, "  fixed / float / single / none  %ld / %ld / %ld / %ld\n", fixed_, floats_, singles_, none_);
    if (latency_.count() > 0) {
      std::fprintf(stderr, "  latency                median %.2f ms  p99 %.2f ms  max %.2f ms (last byte of the epoch to its solution written)\n",
                   latency_.quantile(0.5), latency_.quantile(0.99), latencyMax_);
    }
    if (ages_.count() > 0) std::fprintf(stderr, "  base age               median %.2f s  max %.2f s\n", ages_.quantile(0.5), ages_.quantile(1.0));
    for (const Input& in : in_) {
      const auto& k = in.source->counters();
      std::fprintf(stderr, "  %-5s stream           %lld bytes, %lld connections, %lld failed attempts, %lld gaps (%.1f s without data)\n",
                   in.role.c_str(), static_cast<long long>(k.bytes), static_cast<long long>(k.connects),
                   static_cast<long long>(k.failedAttempts), static_cast<long long>(k.drops), k.gapSeconds);
      if (in.reader && in.reader->skipped()) {
        std::fprintf(stderr, "  %-5s input            %lld malformed frames/epochs skipped\n", in.role.c_str(),
                     static_cast<long long>(in.reader->skipped()));
      }
    }
    for (const Output* o : {&posOut_, &nmeaOut_}) {
      if (!o->sink) continue;
      const auto& k = o->sink->counters();
      // Network outputs only: a server, or a client that connected or lost rows (a file or
      // standard output has neither).
      if (o->sink->boundPort() == 0 && k.clients == 0 && k.discarded == 0) continue;
      std::fprintf(stderr, "  %-9s output       %s: %lld bytes, %lld clients, %lld dropped, %lld bytes nobody received\n", o->what,
                   o->sink->name().c_str(), static_cast<long long>(k.bytes), static_cast<long long>(k.clients),
                   static_cast<long long>(k.drops), static_cast<long long>(k.discarded));
    }
    std::fprintf(stderr, "  time                   %8.1f s%s\n", wall, signalled ? " (stopped by a signal)" : "");
  }

  const LiveOptions& opt_;
  EphemerisStore& nav_;
  RtkSolver solver_;
  std::optional<Eigen::Vector3d> basePos_;
  PosWriterOptions popt_;
  Output posOut_, nmeaOut_;
  std::ofstream latFile_;
  std::unique_ptr<NmeaWriter> nmea_;
  std::unique_ptr<PosWriter> writer_;
  std::mutex ggaMutex_;
  std::string gga_;
  Input in_[2];
  ChunkQueue queue_;
  ObsEpoch roverEpoch_, baseEpoch_;
  Clock::time_point roverArrival_{};
  std::optional<GpsTime> firstRoverTime_, lastBaseTime_;
  long epochs_ = 0, baseEpochs_ = 0, fixed_ = 0, floats_ = 0, singles_ = 0, none_ = 0;
  QuantileHistogram latency_, ages_;
  double latencyMax_ = 0.0;
};

}  // namespace

int runLive(const LiveOptions& opt, const RtkConfig& cfg, const SppConfig& sppCfg, EphemerisStore& nav) {
  LiveSession session(opt, cfg, sppCfg, nav);
  return session.run();
}

}  // namespace gvins::rtklive
