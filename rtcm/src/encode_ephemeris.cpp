// Ephemeris message encoding: the inverse of decode_ephemeris.cpp, field by field in the order
// of RTCM 10403.3 (1019, 1020, 1042, 1044, 1045, 1046).
#include <cmath>

#include "gvins/base/constants.hpp"
#include "gvins/rtcm/accuracy_tables.hpp"
#include "gvins/rtcm/bit_writer.hpp"
#include "gvins/rtcm/encoder.hpp"

namespace gvins::rtcm {
namespace {

constexpr double kSc = constants::kPi;

/// v in units of 2^e, rounded.
std::int64_t q(double v, int e) { return std::llround(std::ldexp(v, -e)); }
std::uint64_t uq(double v, int e, const char* field) {
  const std::int64_t r = q(v, e);
  if (r < 0) throw MessageError(field, "negative value for an unsigned field");
  return static_cast<std::uint64_t>(r);
}

void gpsOrbit(BitWriter& w, const KeplerEphemeris& e, const char* crs, const char* dn, const char* m0,
              const char* cuc, const char* ecc, const char* cus, const char* sqa) {
  w.s(16, q(e.crs, -5), crs);
  w.s(16, q(e.deltaN / kSc, -43), dn);
  w.s(32, q(e.m0 / kSc, -31), m0);
  w.s(16, q(e.cuc, -29), cuc);
  w.u(32, uq(e.e, -33, ecc), ecc);
  w.s(16, q(e.cus, -29), cus);
  w.u(32, uq(e.sqrtA, -19, sqa), sqa);
}

double towOf(const GpsTime& t) { return t.tow(); }

/// DF076/DF452: the week of transmission (IS-GPS-200 20.3.3.3.1.1), which differs from toe's
/// week when a record for the next week is sent before the rollover. The transmission time is
/// used when it is set and within half a week of toe.
std::uint64_t lnavWeek(const KeplerEphemeris& e) {
  const bool ttrUsable = e.ttr != GpsTime{} && std::abs(e.ttr - e.toe) < kSecondsPerWeek / 2;
  return static_cast<std::uint64_t>((ttrUsable ? e.ttr : e.toe).week() % 1024);
}

std::vector<std::uint8_t> encodeGps(const KeplerEphemeris& e, int station) {
  (void)station;
  BitWriter w;
  w.u(12, 1019, "DF002 message number");
  w.u(6, e.sat.prn, "DF009 satellite ID");
  w.u(10, lnavWeek(e), "DF076 GPS week number");
  w.u(4, static_cast<std::uint64_t>(uraIndex(e.ura)), "DF077 SV accuracy");
  w.u(2, static_cast<std::uint64_t>(e.codesOnL2), "DF078 code on L2");
  w.s(14, q(e.iDot / kSc, -43), "DF079 IDOT");
  w.u(8, static_cast<std::uint64_t>(e.iode), "DF071 IODE");
  w.u(16, uq(towOf(e.toc), 4, "DF081 toc"), "DF081 toc");
  w.s(8, q(e.af2, -55), "DF082 af2");
  w.s(16, q(e.af1, -43), "DF083 af1");
  w.s(22, q(e.af0, -31), "DF084 af0");
  w.u(10, static_cast<std::uint64_t>(e.iodc), "DF085 IODC");
  gpsOrbit(w, e, "DF086 Crs", "DF087 delta n", "DF088 M0", "DF089 Cuc", "DF090 eccentricity",
           "DF091 Cus", "DF092 sqrt A");
  w.u(16, uq(e.toeSeconds, 4, "DF093 toe"), "DF093 toe");
  w.s(16, q(e.cic, -29), "DF094 Cic");
  w.s(32, q(e.omega0 / kSc, -31), "DF095 Omega0");
  w.s(16, q(e.cis, -29), "DF096 Cis");
  w.s(32, q(e.i0 / kSc, -31), "DF097 i0");
  w.s(16, q(e.crc, -5), "DF098 Crc");
  w.s(32, q(e.omega / kSc, -31), "DF099 omega");
  w.s(24, q(e.omegaDot / kSc, -43), "DF100 OMEGADOT");
  w.s(8, q(e.tgd[0], -31), "DF101 tGD");
  w.u(6, static_cast<std::uint64_t>(e.health), "DF102 SV health");
  w.u(1, static_cast<std::uint64_t>(e.l2pDataFlag), "DF103 L2 P data flag");
  w.flag(e.fitInterval > 4.0);  // DF137: 0 = 4 hours, 1 = longer (IS-GPS-200 20.3.3.4.3.1)
  return Encoder::frame(w.bytes());
}

std::vector<std::uint8_t> encodeQzss(const KeplerEphemeris& e) {
  BitWriter w;
  w.u(12, 1044, "DF002 message number");
  w.u(4, e.sat.prn, "DF429 QZSS satellite ID");
  w.u(16, uq(towOf(e.toc), 4, "DF430 toc"), "DF430 toc");
  w.s(8, q(e.af2, -55), "DF431 af2");
  w.s(16, q(e.af1, -43), "DF432 af1");
  w.s(22, q(e.af0, -31), "DF433 af0");
  w.u(8, static_cast<std::uint64_t>(e.iode), "DF434 IODE");
  gpsOrbit(w, e, "DF435 Crs", "DF436 delta n", "DF437 M0", "DF438 Cuc", "DF439 eccentricity",
           "DF440 Cus", "DF441 sqrt A");
  w.u(16, uq(e.toeSeconds, 4, "DF442 toe"), "DF442 toe");
  w.s(16, q(e.cic, -29), "DF443 Cic");
  w.s(32, q(e.omega0 / kSc, -31), "DF444 Omega0");
  w.s(16, q(e.cis, -29), "DF445 Cis");
  w.s(32, q(e.i0 / kSc, -31), "DF446 i0");
  w.s(16, q(e.crc, -5), "DF447 Crc");
  w.s(32, q(e.omega / kSc, -31), "DF448 omega");
  w.s(24, q(e.omegaDot / kSc, -43), "DF449 OMEGADOT");
  w.s(14, q(e.iDot / kSc, -43), "DF450 IDOT");
  w.u(2, static_cast<std::uint64_t>(e.codesOnL2), "DF451 codes on L2");
  w.u(10, lnavWeek(e), "DF452 week number");
  w.u(4, static_cast<std::uint64_t>(uraIndex(e.ura)), "DF453 URA");
  w.u(6, static_cast<std::uint64_t>(e.health), "DF454 SV health");
  w.s(8, q(e.tgd[0], -31), "DF455 TGD");
  w.u(10, static_cast<std::uint64_t>(e.iodc), "DF456 IODC");
  w.flag(e.fitInterval != 2.0);  // DF457: 0 = 2 hours
  return Encoder::frame(w.bytes());
}

std::vector<std::uint8_t> encodeBeidou(const KeplerEphemeris& e) {
  BitWriter w;
  int bdtWeek = 0;
  double tocSow = 0.0;
  gpstToBdt(e.toc, bdtWeek, tocSow);
  w.u(12, 1042, "DF002 message number");
  w.u(6, e.sat.prn, "DF488 BeiDou satellite ID");
  w.u(13, static_cast<std::uint64_t>(e.week % 8192), "DF489 BeiDou week number");
  w.u(4, static_cast<std::uint64_t>(uraIndex(e.ura)), "DF490 URAI");
  w.s(14, q(e.iDot / kSc, -43), "DF491 IDOT");
  w.u(5, static_cast<std::uint64_t>(e.iode), "DF492 AODE");
  w.u(17, uq(tocSow, 3, "DF493 toc"), "DF493 toc");
  w.s(11, q(e.af2, -66), "DF494 a2");
  w.s(22, q(e.af1, -50), "DF495 a1");
  w.s(24, q(e.af0, -33), "DF496 a0");
  w.u(5, static_cast<std::uint64_t>(e.iodc), "DF497 AODC");
  w.s(18, q(e.crs, -6), "DF498 Crs");
  w.s(16, q(e.deltaN / kSc, -43), "DF499 delta n");
  w.s(32, q(e.m0 / kSc, -31), "DF500 M0");
  w.s(18, q(e.cuc, -31), "DF501 Cuc");
  w.u(32, uq(e.e, -33, "DF502 eccentricity"), "DF502 eccentricity");
  w.s(18, q(e.cus, -31), "DF503 Cus");
  w.u(32, uq(e.sqrtA, -19, "DF504 sqrt A"), "DF504 sqrt A");
  w.u(17, uq(e.toeSeconds, 3, "DF505 toe"), "DF505 toe");
  w.s(18, q(e.cic, -31), "DF506 Cic");
  w.s(32, q(e.omega0 / kSc, -31), "DF507 Omega0");
  w.s(18, q(e.cis, -31), "DF508 Cis");
  w.s(32, q(e.i0 / kSc, -31), "DF509 i0");
  w.s(18, q(e.crc, -6), "DF510 Crc");
  w.s(32, q(e.omega / kSc, -31), "DF511 omega");
  w.s(24, q(e.omegaDot / kSc, -43), "DF512 OMEGADOT");
  w.s(10, std::llround(e.tgd[0] * 1e10), "DF513 TGD1");
  w.s(10, std::llround(e.tgd[1] * 1e10), "DF514 TGD2");
  w.u(1, static_cast<std::uint64_t>(e.health & 1), "DF515 SV health");
  return Encoder::frame(w.bytes());
}

std::vector<std::uint8_t> encodeGalileo(const KeplerEphemeris& e, bool inav) {
  BitWriter w;
  int gstWeek = 0;
  double tocSow = 0.0;
  gpstToGst(e.toc, gstWeek, tocSow);
  w.u(12, inav ? 1046 : 1045, "DF002 message number");
  w.u(6, e.sat.prn, "DF252 Galileo satellite ID");
  w.u(12, static_cast<std::uint64_t>(e.week % 4096), "DF289 Galileo week number");
  w.u(10, static_cast<std::uint64_t>(e.iode), "DF290 IODnav");
  w.u(8, static_cast<std::uint64_t>(sisaIndex(e.ura)), "DF291 SISA");
  w.s(14, q(e.iDot / kSc, -43), "DF292 IDOT");
  w.u(14, static_cast<std::uint64_t>(std::llround(tocSow / 60.0)), "DF293 toc");
  w.s(6, q(e.af2, -59), "DF294 af2");
  w.s(21, q(e.af1, -46), "DF295 af1");
  w.s(31, q(e.af0, -34), "DF296 af0");
  gpsOrbit(w, e, "DF297 Crs", "DF298 delta n", "DF299 M0", "DF300 Cuc", "DF301 eccentricity",
           "DF302 Cus", "DF303 sqrt A");
  w.u(14, static_cast<std::uint64_t>(std::llround(e.toeSeconds / 60.0)), "DF304 toe");
  w.s(16, q(e.cic, -29), "DF305 Cic");
  w.s(32, q(e.omega0 / kSc, -31), "DF306 Omega0");
  w.s(16, q(e.cis, -29), "DF307 Cis");
  w.s(32, q(e.i0 / kSc, -31), "DF308 i0");
  w.s(16, q(e.crc, -5), "DF309 Crc");
  w.s(32, q(e.omega / kSc, -31), "DF310 omega");
  w.s(24, q(e.omegaDot / kSc, -43), "DF311 OMEGADOT");
  w.s(10, q(e.tgd[0], -32), "DF312 BGD E1/E5a");
  if (inav) {
    w.s(10, q(e.tgd[1], -32), "DF313 BGD E1/E5b");
    w.u(2, static_cast<std::uint64_t>((e.health >> 7) & 3), "DF316 E5b signal health");
    w.u(1, static_cast<std::uint64_t>((e.health >> 6) & 1), "DF317 E5b data validity");
    w.u(2, static_cast<std::uint64_t>((e.health >> 1) & 3), "DF287 E1-B signal health");
    w.u(1, static_cast<std::uint64_t>(e.health & 1), "DF288 E1-B data validity");
    w.u(2, 0, "reserved");
  } else {
    w.u(2, static_cast<std::uint64_t>((e.health >> 4) & 3), "DF314 E5a signal health");
    w.u(1, static_cast<std::uint64_t>((e.health >> 3) & 1), "DF315 E5a data validity");
    w.u(7, 0, "reserved");
  }
  return Encoder::frame(w.bytes());
}

}  // namespace

std::vector<std::uint8_t> Encoder::ephemeris(const KeplerEphemeris& e) const {
  switch (e.message) {
    case NavMessage::GpsLnav: return encodeGps(e, stationId_);
    case NavMessage::QzssLnav: return encodeQzss(e);
    case NavMessage::BeiDouD1:
    case NavMessage::BeiDouD2: return encodeBeidou(e);
    case NavMessage::GalileoFnav: return encodeGalileo(e, false);
    case NavMessage::GalileoInav: return encodeGalileo(e, true);
  }
  throw MessageError("message", "unknown navigation message");
}

std::vector<std::uint8_t> Encoder::ephemeris(const GlonassEphemeris& g) const {
  BitWriter w;
  w.u(12, 1020, "DF002 message number");
  w.u(6, g.sat.prn, "DF038 satellite ID");
  w.u(5, static_cast<std::uint64_t>(g.frequencyChannel + 7), "DF040 frequency channel number");
  w.u(1, 0, "DF104 almanac health");
  w.u(1, 0, "DF105 almanac health availability");
  w.u(2, 0, "DF106 P1");
  // tk and tb in Moscow time of day (GLONASS ICD 5.1, 4.4).
  const CalendarTime tof = gpstToGlonass(g.tof);
  const int tk30 = static_cast<int>(std::llround((tof.hour * 3600.0 + tof.minute * 60.0 + tof.second) / 30.0)) % 2880;
  w.u(5, static_cast<std::uint64_t>(tk30 / 120), "DF107 tk hours");
  w.u(6, static_cast<std::uint64_t>((tk30 / 2) % 60), "DF107 tk minutes");
  w.u(1, static_cast<std::uint64_t>(tk30 % 2), "DF107 tk 30 s");
  w.u(1, static_cast<std::uint64_t>(g.health & 1), "DF108 MSB of Bn");
  w.u(1, 0, "DF109 P2");
  const CalendarTime toe = gpstToGlonass(g.toe);
  const auto tb = std::llround((toe.hour * 3600.0 + toe.minute * 60.0 + toe.second) / 900.0);
  w.u(7, static_cast<std::uint64_t>(tb), "DF110 tb");
  const char* names[9] = {"DF111 xn'", "DF112 xn", "DF113 xn''", "DF114 yn'", "DF115 yn",
                          "DF116 yn''", "DF117 zn'", "DF118 zn", "DF119 zn''"};
  for (int k = 0; k < 3; ++k) {
    w.sm(24, q(g.velocity[k] * 1e-3, -20), names[3 * k]);
    w.sm(27, q(g.position[k] * 1e-3, -11), names[3 * k + 1]);
    w.sm(5, q(g.acceleration[k] * 1e-3, -30), names[3 * k + 2]);
  }
  w.u(1, 0, "DF120 P3");
  w.sm(11, q(g.gammaN, -40), "DF121 gamma n");
  w.u(2, 0, "DF122 P");
  w.u(1, 0, "DF123 ln");
  w.sm(22, q(g.tauN, -30), "DF124 tau n");
  w.sm(5, q(g.deltaTauN, -30), "DF125 delta tau n");
  w.u(5, static_cast<std::uint64_t>(g.age), "DF126 En");
  w.u(1, 0, "DF127 P4");
  w.u(4, static_cast<std::uint64_t>(glonassFtIndex(g.accuracy)), "DF128 FT");
  // NT: day within the four-year interval starting 1 January 1996 + 4 (N4 - 1).
  const std::int64_t days = daysFromCivil(toe.year, toe.month, toe.day);
  const int n4 = (toe.year - 1996) / 4 + 1;
  const std::int64_t nt = days - daysFromCivil(1996 + 4 * (n4 - 1), 1, 1) + 1;
  w.u(11, static_cast<std::uint64_t>(nt), "DF129 NT");
  w.u(2, 1, "DF130 M");  // GLONASS-M
  w.u(1, 1, "DF131 availability of additional data");
  w.u(11, 0, "DF132 NA");
  w.sm(32, 0, "DF133 tau c");
  w.u(5, static_cast<std::uint64_t>(n4), "DF134 N4");
  w.sm(22, 0, "DF135 tau GPS");
  w.u(1, 0, "DF136 ln");
  w.u(7, 0, "reserved");
  return frame(w.bytes());
}

}  // namespace gvins::rtcm
