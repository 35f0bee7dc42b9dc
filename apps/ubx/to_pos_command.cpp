// gvins-ubx to-pos FILE|- -o OUT.pos
// The receiver's own navigation solutions (UBX-NAV-PVT) as an RTKLIB .pos file through the
// project's .pos writer, one row per NAV-PVT epoch with a 3D fix:
//   time   GPST = the GPS week of the stream and iTOW (ms). The week is that of the latest
//          RXM-RAWX epoch or NAV-TIMEGPS (weekValid) before the NAV-PVT, else of the first one
//          after it, taking the week that puts iTOW nearest to it (a rollover in between is
//          handled); a stream with neither takes it from NAV-PVT's own UTC date (validDate,
//          validTime, fullyResolved) and the leap-second table. Without any, the row is left out.
//   Q      carrSoln 2 -> 1 (fix), carrSoln 1 -> 2 (float), diffSoln -> 4 (DGPS), else 5 (single);
//          gnssFixOK clear, no fix, dead reckoning only, time only and 2D fixes are left out.
//   sigma  hAcc split equally over north and east (sdn = sde = hAcc/sqrt 2), sdu = vAcc; the
//          velocity (velN, velE, -velD) gets sAcc split equally over its three components.
// Rows per Q and the rows left out are summarised on stderr.
#include <cmath>
#include <deque>
#include <iostream>
#include <map>

#include "commands.hpp"
#include "gvins/base/atomic_output_file.hpp"
#include "gvins/base/constants.hpp"
#include "gvins/base/geodetic.hpp"
#include "gvins/base/local_frame.hpp"
#include "gvins/gnss/pos_writer.hpp"
#include "stream_summary.hpp"
#include "ubx_summary.hpp"

namespace gvins::ubx_app {

namespace {

std::optional<SolutionQuality> qualityOf(ubx::NavPvtSolution s) {
  switch (s) {
    case ubx::NavPvtSolution::RtkFixed: return SolutionQuality::Fix;
    case ubx::NavPvtSolution::RtkFloat: return SolutionQuality::Float;
    case ubx::NavPvtSolution::Differential: return SolutionQuality::Dgps;
    case ubx::NavPvtSolution::Single: return SolutionQuality::Single;
    case ubx::NavPvtSolution::TwoD:
    case ubx::NavPvtSolution::None: break;
  }
  return std::nullopt;
}

PositionSolution solutionOf(const ubx::NavPvt& p, const GpsTime& t, SolutionQuality q) {
  const double lat = p.latDeg * constants::kDegToRad, lon = p.lonDeg * constants::kDegToRad;
  const Eigen::Matrix3d r = ecefToEnuRotation(lat, lon);  // ENU = r * ECEF
  PositionSolution s;
  s.time = t;
  s.quality = q;
  s.numSatellites = p.numSv;
  s.position = geodeticToEcef({lat, lon, p.height});
  const Eigen::Vector3d posVar(p.hAcc * p.hAcc / 2.0, p.hAcc * p.hAcc / 2.0, p.vAcc * p.vAcc);
  s.positionCovariance = r.transpose() * posVar.asDiagonal() * r;
  s.velocity = r.transpose() * Eigen::Vector3d(p.velE, p.velN, -p.velD);
  s.velocityCovariance = r.transpose() * Eigen::Matrix3d::Identity() * (p.sAcc * p.sAcc / 3.0) * r;
  return s;
}

/// NAV-PVT epochs to rows: the week bookkeeping and the counts of the summary.
class PvtRows {
 public:
  explicit PvtRows(PosWriter& w) : writer_(w) {}

  /// Another GPST of the stream (RXM-RAWX epoch, NAV-TIMEGPS): resolves the waiting NAV-PVTs.
  void reference(const GpsTime& t) {
    ref_ = t;
    while (!pending_.empty()) {
      emit(pending_.front(), ubx::timeOfWeekNear(pending_.front().iTow * 1e-3, t));
      pending_.pop_front();
    }
  }

  void add(const ubx::NavPvt& p) {
    ++navPvt_;
    if (ref_) {
      emit(p, ubx::timeOfWeekNear(p.iTow * 1e-3, *ref_));
    } else {
      // A long stretch without any week source: the waiting rows take their own UTC dates (in
      // stream order) rather than growing the queue without bound.
      if (pending_.size() >= kMaxPending) finish();
      pending_.push_back(p);
    }
  }

  /// End of stream: NAV-PVTs never followed by a week take it from their own UTC date.
  void finish() {
    for (const ubx::NavPvt& p : pending_) resolveByUtc(p);
    pending_.clear();
  }

  std::int64_t navPvt() const { return navPvt_; }
  std::int64_t rows() const { return rows_; }

  void print(std::ostream& out) const {
    out << "rows per Q     ";
    for (const auto& [q, n] : perQ_) out << " Q=" << q << " " << n;
    if (perQ_.empty()) out << " none";
    out << " (1 fix, 2 float, 4 DGPS, 5 single)\n";
    out << "left out       " << noFix_ << " without a 3D fix (gnssFixOK clear, no fix, dead reckoning or time only), "
        << twoD_ << " 2D fixes, " << noWeek_ << " without a GPS week\n";
    if (byUtc_ > 0) out << "week           " << byUtc_ << " rows dated by NAV-PVT's UTC date (no RXM-RAWX or NAV-TIMEGPS)\n";
  }

 private:
  static constexpr std::size_t kMaxPending = 100000;

  void resolveByUtc(const ubx::NavPvt& p) {
    if (const auto near = ubx::navPvtUtcAsGpst(p)) {
      ++byUtc_;
      emit(p, ubx::timeOfWeekNear(p.iTow * 1e-3, *near));
    } else {
      ++noWeek_;
    }
  }

  void emit(const ubx::NavPvt& p, const GpsTime& t) {
    const ubx::NavPvtSolution kind = ubx::navPvtSolution(p);
    const auto q = qualityOf(kind);
    if (!q) {
      ++(kind == ubx::NavPvtSolution::TwoD ? twoD_ : noFix_);
      return;
    }
    writer_.write(solutionOf(p, t, *q));
    ++perQ_[static_cast<int>(*q)];
    ++rows_;
  }

  PosWriter& writer_;
  std::optional<GpsTime> ref_;
  std::deque<ubx::NavPvt> pending_;
  std::map<int, std::int64_t> perQ_;
  std::int64_t navPvt_ = 0, rows_ = 0, noFix_ = 0, twoD_ = 0, noWeek_ = 0, byUtc_ = 0;
};

}  // namespace

int runToPos(CommandLine& cl) {
  std::string path, out;
  while (cl.next()) {
    if (cl.is("-o")) {
      out = cl.value();
    } else {
      const std::string& a = cl.operand();
      if (!path.empty()) cl.error("to-pos: more than one input");
      path = a;
    }
  }
  if (path.empty()) cl.error("to-pos: no input (FILE or -)");
  if (out.empty()) cl.error("to-pos: no output file (-o OUT.pos)");
  const std::string name = path == "-" ? "<stdin>" : path;
  ubx::DecoderOptions opt;
  opt.streamName = name;
  opt.decodeNavigation = false;  // SFRBX is not needed for the receiver's own solutions
  ubx::Decoder dec(opt);

  PosWriterOptions wo;
  wo.program = "gvins-ubx to-pos";
  wo.headerFields = {{"inp file", name}, {"source", "UBX-NAV-PVT (the receiver's own real-time solution)"}};
  wo.notes = {"time=GPS week of RXM-RAWX/NAV-TIMEGPS + NAV-PVT iTOW (ms),height=NAV-PVT height (ellipsoid)",
              "sdn=sde=hAcc/sqrt(2),sdu=vAcc,sdvn=sdve=sdvu=sAcc/sqrt(3): u-blox accuracy estimates"};
  AtomicOutputFile file(out);
  PosWriter writer(file.stream(), wo);
  PvtRows rows(writer);
  std::FILE* in = rtcm_app::openInput(path);
  decodeAll(in, dec, [&](const ubx::Decoded& item) {
    if (const auto* p = std::get_if<ubx::NavPvt>(&item)) {
      rows.add(*p);
    } else if (const auto* e = std::get_if<ObsEpoch>(&item)) {
      rows.reference(e->time);
    } else if (const auto* g = std::get_if<ubx::NavTimeGps>(&item)) {
      if (g->weekValid() && g->week > 0 && g->iTow < 604800000u) {
        rows.reference(GpsTime::fromWeekTow(g->week, g->iTow * 1e-3 + g->fTow * 1e-9));
      }
    }
  });
  if (in != stdin) std::fclose(in);
  // RAWX epochs without a usable measurement are not delivered, but their time is known.
  if (const auto t = dec.lastEpochTime()) rows.reference(*t);
  rows.finish();
  const ubx::DecoderStats& st = dec.stats();
  if (rows.navPvt() == 0) {
    throw std::runtime_error("to-pos: " + name + ": no NAV-PVT message in " + std::to_string(st.stream.ubxFrames) +
                             " UBX frames (" + std::to_string(st.stream.bytes) + " bytes, " +
                             std::to_string(st.malformed) + " malformed messages); nothing to convert");
  }
  writer.finish();
  file.commit();
  std::cerr << "wrote " << out << ": " << rows.rows() << " rows from " << rows.navPvt() << " NAV-PVT messages of "
            << name << "\n";
  rows.print(std::cerr);
  if (st.malformed > 0 || st.stream.ubxChecksumFailures > 0) {
    std::cerr << "skipped        " << st.malformed << " malformed messages, " << st.stream.ubxChecksumFailures
              << " UBX checksum failures\n";
    for (const auto& issue : st.issues) {
      std::cerr << "  byte " << issue.offset << ": " << messageName(issue.type) << " " << issue.what << "\n";
    }
  }
  return 0;
}

}  // namespace gvins::ubx_app
