// Broadcast ephemeris messages of RTCM 10403.3 section 3.5: 1019 GPS (DF071-DF103, DF137),
// 1020 GLONASS (DF104-DF136), 1042 BeiDou (DF488-DF515), 1044 QZSS (DF429-DF457), 1045 Galileo
// F/NAV and 1046 Galileo I/NAV (DF252, DF287-DF317). Scale factors are those of the ICDs the
// fields copy (IS-GPS-200 table 20-III, GLONASS ICD 5.1 table 4.5, BDS-SIS-ICD B1I table 5-9,
// IS-QZSS-PNT, Galileo OS SIS ICD table 60).
#include <cmath>

#include "broadcast_times.hpp"
#include "decoder_state.hpp"
#include "gvins/base/constants.hpp"
#include "gvins/rtcm/accuracy_tables.hpp"

namespace gvins::rtcm {
namespace {

constexpr double kSc = constants::kPi;  // semicircles to radians (ICD value of pi)

double sc(std::int64_t v, int e) { return std::ldexp(static_cast<double>(v), e); }
double uc(std::uint64_t v, int e) { return std::ldexp(static_cast<double>(v), e); }

// Galileo and BeiDou times: full week numbers in the system's own count.
void finishTimes(Decoder::State& s, KeplerEphemeris& e, int fullWeek, double toe, double toc,
                 bool gst, bool bdt) {
  auto at = [&](double sow) {
    if (bdt) return bdtToGpst(fullWeek, sow);
    if (gst) return gstToGpst(fullWeek, sow);
    return GpsTime::fromWeekTow(fullWeek, sow);
  };
  e.toe = at(toe);
  e.toc = nearWeek(at(toc), e.toe);
  e.toeSeconds = toe;
  e.week = fullWeek;
  e.ttr = s.ref;
}

// GPS/QZSS LNAV times. DF076/DF452 is the week of transmission modulo 1024 (IS-GPS-200
// 20.3.3.3.1.1); toe may lie in the next week when a record is sent before the rollover. The
// transmission time is the reference (the time of reception) when that falls in the transmitted
// week; otherwise (no usable reference) toe is taken to lie in the transmitted week and stands
// for the transmission time.
void lnavTimes(Decoder::State& s, KeplerEphemeris& e, int week10, double toe, double toc) {
  const int week = resolveWeek(week10, 10, s.ref);
  const GpsTime ttr = s.ref.week() == week ? s.ref : GpsTime::fromWeekTow(week, toe);
  e.toe = nearWeek(GpsTime::fromWeekTow(week, toe), ttr);
  e.toc = nearWeek(GpsTime::fromWeekTow(week, toc), e.toe);
  e.toeSeconds = toe;
  e.week = e.toe.week();
  e.ttr = ttr;
}

void emit(Decoder::State& s, KeplerEphemeris&& e) {
  ++s.stats.ephemerides;
  s.out.emplace_back(std::move(e));
}

}  // namespace

void decodeGpsEphemeris(Decoder::State& s, BitReader& r) {
  r.need(488 - 12, "1019 body");
  KeplerEphemeris e;
  e.message = NavMessage::GpsLnav;
  const int id = static_cast<int>(r.u(6, "DF009 satellite ID"));
  const int week10 = static_cast<int>(r.u(10, "DF076 GPS week number"));
  e.ura = uraMetres(static_cast<int>(r.u(4, "DF077 SV accuracy")));
  e.codesOnL2 = static_cast<int>(r.u(2, "DF078 code on L2"));
  e.iDot = sc(r.s(14, "DF079 IDOT"), -43) * kSc;
  e.iode = static_cast<int>(r.u(8, "DF071 IODE"));
  const double toc = uc(r.u(16, "DF081 toc"), 4);
  e.af2 = sc(r.s(8, "DF082 af2"), -55);
  e.af1 = sc(r.s(16, "DF083 af1"), -43);
  e.af0 = sc(r.s(22, "DF084 af0"), -31);
  e.iodc = static_cast<int>(r.u(10, "DF085 IODC"));
  e.crs = sc(r.s(16, "DF086 Crs"), -5);
  e.deltaN = sc(r.s(16, "DF087 delta n"), -43) * kSc;
  e.m0 = sc(r.s(32, "DF088 M0"), -31) * kSc;
  e.cuc = sc(r.s(16, "DF089 Cuc"), -29);
  e.e = uc(r.u(32, "DF090 eccentricity"), -33);
  e.cus = sc(r.s(16, "DF091 Cus"), -29);
  e.sqrtA = uc(r.u(32, "DF092 sqrt A"), -19);
  const double toe = uc(r.u(16, "DF093 toe"), 4);
  e.cic = sc(r.s(16, "DF094 Cic"), -29);
  e.omega0 = sc(r.s(32, "DF095 Omega0"), -31) * kSc;
  e.cis = sc(r.s(16, "DF096 Cis"), -29);
  e.i0 = sc(r.s(32, "DF097 i0"), -31) * kSc;
  e.crc = sc(r.s(16, "DF098 Crc"), -5);
  e.omega = sc(r.s(32, "DF099 omega"), -31) * kSc;
  e.omegaDot = sc(r.s(24, "DF100 OMEGADOT"), -43) * kSc;
  e.tgd[0] = sc(r.s(8, "DF101 tGD"), -31);
  e.health = static_cast<int>(r.u(6, "DF102 SV health"));
  e.l2pDataFlag = static_cast<int>(r.u(1, "DF103 L2 P data flag"));
  e.fitInterval = gpsFitHours(r.flag("DF137 fit interval"), e.iodc);
  e.sat = SatId(System::Gps, id);
  if (!e.sat.valid()) throw MessageError("DF009 satellite ID", "GPS satellite ID " + std::to_string(id) + " is not 1-32");
  if (toe >= kSecondsPerWeek || toc >= kSecondsPerWeek) throw MessageError("DF093 toe", "beyond a week");
  lnavTimes(s, e, week10, toe, toc);
  emit(s, std::move(e));
}

void decodeQzssEphemeris(Decoder::State& s, BitReader& r) {
  r.need(485 - 12, "1044 body");
  KeplerEphemeris e;
  e.message = NavMessage::QzssLnav;
  const int id = static_cast<int>(r.u(4, "DF429 QZSS satellite ID"));
  const double toc = uc(r.u(16, "DF430 toc"), 4);
  e.af2 = sc(r.s(8, "DF431 af2"), -55);
  e.af1 = sc(r.s(16, "DF432 af1"), -43);
  e.af0 = sc(r.s(22, "DF433 af0"), -31);
  e.iode = static_cast<int>(r.u(8, "DF434 IODE"));
  e.crs = sc(r.s(16, "DF435 Crs"), -5);
  e.deltaN = sc(r.s(16, "DF436 delta n"), -43) * kSc;
  e.m0 = sc(r.s(32, "DF437 M0"), -31) * kSc;
  e.cuc = sc(r.s(16, "DF438 Cuc"), -29);
  e.e = uc(r.u(32, "DF439 eccentricity"), -33);
  e.cus = sc(r.s(16, "DF440 Cus"), -29);
  e.sqrtA = uc(r.u(32, "DF441 sqrt A"), -19);
  const double toe = uc(r.u(16, "DF442 toe"), 4);
  e.cic = sc(r.s(16, "DF443 Cic"), -29);
  e.omega0 = sc(r.s(32, "DF444 Omega0"), -31) * kSc;
  e.cis = sc(r.s(16, "DF445 Cis"), -29);
  e.i0 = sc(r.s(32, "DF446 i0"), -31) * kSc;
  e.crc = sc(r.s(16, "DF447 Crc"), -5);
  e.omega = sc(r.s(32, "DF448 omega"), -31) * kSc;
  e.omegaDot = sc(r.s(24, "DF449 OMEGADOT"), -43) * kSc;
  e.iDot = sc(r.s(14, "DF450 IDOT"), -43) * kSc;
  e.codesOnL2 = static_cast<int>(r.u(2, "DF451 codes on L2"));
  const int week10 = static_cast<int>(r.u(10, "DF452 week number"));
  e.ura = uraMetres(static_cast<int>(r.u(4, "DF453 URA")));
  e.health = static_cast<int>(r.u(6, "DF454 SV health"));
  e.tgd[0] = sc(r.s(8, "DF455 TGD"), -31);
  e.iodc = static_cast<int>(r.u(10, "DF456 IODC"));
  // DF457: 0 = fit interval of 2 hours, 1 = longer (IS-QZSS-PNT 4.1.2); stored as 2 h or 0 (unknown).
  e.fitInterval = r.flag("DF457 fit interval") ? 0.0 : 2.0;
  e.sat = SatId(System::Qzss, id);
  if (!e.sat.valid()) throw MessageError("DF429 QZSS satellite ID", "QZSS satellite ID " + std::to_string(id) + " is not 1-10");
  if (toe >= kSecondsPerWeek || toc >= kSecondsPerWeek) throw MessageError("DF442 toe", "beyond a week");
  lnavTimes(s, e, week10, toe, toc);
  emit(s, std::move(e));
}

void decodeBeidouEphemeris(Decoder::State& s, BitReader& r) {
  r.need(511 - 12, "1042 body");
  KeplerEphemeris e;
  const int id = static_cast<int>(r.u(6, "DF488 BeiDou satellite ID"));
  const int week = static_cast<int>(r.u(13, "DF489 BeiDou week number"));
  e.ura = uraMetres(static_cast<int>(r.u(4, "DF490 URAI")));
  e.iDot = sc(r.s(14, "DF491 IDOT"), -43) * kSc;
  e.iode = static_cast<int>(r.u(5, "DF492 AODE"));
  const double toc = uc(r.u(17, "DF493 toc"), 3);
  e.af2 = sc(r.s(11, "DF494 a2"), -66);
  e.af1 = sc(r.s(22, "DF495 a1"), -50);
  e.af0 = sc(r.s(24, "DF496 a0"), -33);
  e.iodc = static_cast<int>(r.u(5, "DF497 AODC"));
  e.crs = sc(r.s(18, "DF498 Crs"), -6);
  e.deltaN = sc(r.s(16, "DF499 delta n"), -43) * kSc;
  e.m0 = sc(r.s(32, "DF500 M0"), -31) * kSc;
  e.cuc = sc(r.s(18, "DF501 Cuc"), -31);
  e.e = uc(r.u(32, "DF502 eccentricity"), -33);
  e.cus = sc(r.s(18, "DF503 Cus"), -31);
  e.sqrtA = uc(r.u(32, "DF504 sqrt A"), -19);
  const double toe = uc(r.u(17, "DF505 toe"), 3);
  e.cic = sc(r.s(18, "DF506 Cic"), -31);
  e.omega0 = sc(r.s(32, "DF507 Omega0"), -31) * kSc;
  e.cis = sc(r.s(18, "DF508 Cis"), -31);
  e.i0 = sc(r.s(32, "DF509 i0"), -31) * kSc;
  e.crc = sc(r.s(18, "DF510 Crc"), -6);
  e.omega = sc(r.s(32, "DF511 omega"), -31) * kSc;
  e.omegaDot = sc(r.s(24, "DF512 OMEGADOT"), -43) * kSc;
  e.tgd[0] = static_cast<double>(r.s(10, "DF513 TGD1")) * 1e-10;
  e.tgd[1] = static_cast<double>(r.s(10, "DF514 TGD2")) * 1e-10;
  e.health = static_cast<int>(r.u(1, "DF515 SV health"));
  e.sat = SatId(System::BeiDou, id);
  if (!e.sat.valid()) throw MessageError("DF488 BeiDou satellite ID", "BeiDou satellite ID " + std::to_string(id) + " is not 1-63");
  if (toe >= kSecondsPerWeek || toc >= kSecondsPerWeek) throw MessageError("DF505 toe", "beyond a week");
  e.message = isBeiDouGeo(e.sat) ? NavMessage::BeiDouD2 : NavMessage::BeiDouD1;
  finishTimes(s, e, week, toe, toc, false, true);
  learnAbsoluteTime(s, e.toe);
  e.ttr = s.ref;
  emit(s, std::move(e));
}

void decodeGalileoEphemeris(Decoder::State& s, BitReader& r, bool inav) {
  r.need((inav ? 504 : 496) - 12, inav ? "1046 body" : "1045 body");
  KeplerEphemeris e;
  e.message = inav ? NavMessage::GalileoInav : NavMessage::GalileoFnav;
  const int id = static_cast<int>(r.u(6, "DF252 Galileo satellite ID"));
  const int week = static_cast<int>(r.u(12, "DF289 Galileo week number"));
  e.iode = static_cast<int>(r.u(10, "DF290 IODnav"));
  e.iodc = e.iode;
  e.ura = sisaMetres(static_cast<int>(r.u(8, "DF291 SISA")));
  e.iDot = sc(r.s(14, "DF292 IDOT"), -43) * kSc;
  const double toc = static_cast<double>(r.u(14, "DF293 toc")) * 60.0;
  e.af2 = sc(r.s(6, "DF294 af2"), -59);
  e.af1 = sc(r.s(21, "DF295 af1"), -46);
  e.af0 = sc(r.s(31, "DF296 af0"), -34);
  e.crs = sc(r.s(16, "DF297 Crs"), -5);
  e.deltaN = sc(r.s(16, "DF298 delta n"), -43) * kSc;
  e.m0 = sc(r.s(32, "DF299 M0"), -31) * kSc;
  e.cuc = sc(r.s(16, "DF300 Cuc"), -29);
  e.e = uc(r.u(32, "DF301 eccentricity"), -33);
  e.cus = sc(r.s(16, "DF302 Cus"), -29);
  e.sqrtA = uc(r.u(32, "DF303 sqrt A"), -19);
  const double toe = static_cast<double>(r.u(14, "DF304 toe")) * 60.0;
  e.cic = sc(r.s(16, "DF305 Cic"), -29);
  e.omega0 = sc(r.s(32, "DF306 Omega0"), -31) * kSc;
  e.cis = sc(r.s(16, "DF307 Cis"), -29);
  e.i0 = sc(r.s(32, "DF308 i0"), -31) * kSc;
  e.crc = sc(r.s(16, "DF309 Crc"), -5);
  e.omega = sc(r.s(32, "DF310 omega"), -31) * kSc;
  e.omegaDot = sc(r.s(24, "DF311 OMEGADOT"), -43) * kSc;
  e.tgd[0] = sc(r.s(10, "DF312 BGD E1/E5a"), -32);
  if (inav) {
    e.tgd[1] = sc(r.s(10, "DF313 BGD E1/E5b"), -32);
    const int e5bHs = static_cast<int>(r.u(2, "DF316 E5b signal health"));
    const int e5bDvs = static_cast<int>(r.u(1, "DF317 E5b data validity"));
    const int e1bHs = static_cast<int>(r.u(2, "DF287 E1-B signal health"));
    const int e1bDvs = static_cast<int>(r.u(1, "DF288 E1-B data validity"));
    // RINEX 3.04 table A8 health bits: 0 E1B DVS, 1-2 E1B HS, 3 E5a DVS, 4-5 E5a HS,
    // 6 E5b DVS, 7-8 E5b HS; data sources: bit 0 I/NAV E1-B, bit 2 I/NAV E5b-I, bit 9 E5b/E1 clock.
    e.health = e1bDvs | (e1bHs << 1) | (e5bDvs << 6) | (e5bHs << 7);
    e.codesOnL2 = (1 << 0) | (1 << 2) | (1 << 9);
  } else {
    const int e5aHs = static_cast<int>(r.u(2, "DF314 E5a signal health"));
    const int e5aDvs = static_cast<int>(r.u(1, "DF315 E5a data validity"));
    e.health = (e5aDvs << 3) | (e5aHs << 4);
    e.codesOnL2 = (1 << 1) | (1 << 8);  // F/NAV E5a-I, E5a/E1 clock
  }
  e.sat = SatId(System::Galileo, id);
  if (!e.sat.valid()) throw MessageError("DF252 Galileo satellite ID", "Galileo satellite ID " + std::to_string(id) + " is not 1-36");
  if (toe >= kSecondsPerWeek || toc >= kSecondsPerWeek) throw MessageError("DF304 toe", "beyond a week");
  finishTimes(s, e, week, toe, toc, true, false);
  learnAbsoluteTime(s, e.toe);
  e.ttr = s.ref;
  emit(s, std::move(e));
}

void decodeGlonassEphemeris(Decoder::State& s, BitReader& r) {
  r.need(360 - 12, "1020 body");
  GlonassEphemeris g;
  const int slot = static_cast<int>(r.u(6, "DF038 satellite ID"));
  const int fcn = static_cast<int>(r.u(5, "DF040 frequency channel number"));
  r.skip(1 + 1 + 2, "DF104-DF106");
  const int tkH = static_cast<int>(r.u(5, "DF107 tk hours"));
  const int tkM = static_cast<int>(r.u(6, "DF107 tk minutes"));
  const int tkS = static_cast<int>(r.u(1, "DF107 tk 30 s"));
  const int bn = static_cast<int>(r.u(1, "DF108 MSB of Bn"));
  r.skip(1, "DF109 P2");
  const int tb = static_cast<int>(r.u(7, "DF110 tb"));
  const char* names[9] = {"DF111 xn'", "DF112 xn", "DF113 xn''", "DF114 yn'", "DF115 yn",
                          "DF116 yn''", "DF117 zn'", "DF118 zn", "DF119 zn''"};
  for (int k = 0; k < 3; ++k) {
    g.velocity[k] = sc(r.sm(24, names[3 * k]), -20) * 1e3;
    g.position[k] = sc(r.sm(27, names[3 * k + 1]), -11) * 1e3;
    g.acceleration[k] = sc(r.sm(5, names[3 * k + 2]), -30) * 1e3;
  }
  r.skip(1, "DF120 P3");
  g.gammaN = sc(r.sm(11, "DF121 gamma n"), -40);
  r.skip(2, "DF122 P");
  const int ln3 = static_cast<int>(r.u(1, "DF123 ln"));
  g.tauN = sc(r.sm(22, "DF124 tau n"), -30);
  g.deltaTauN = sc(r.sm(5, "DF125 delta tau n"), -30);
  g.age = static_cast<int>(r.u(5, "DF126 En"));
  r.skip(1, "DF127 P4");
  g.accuracy = glonassFtMetres(static_cast<int>(r.u(4, "DF128 FT")));
  const int nt = static_cast<int>(r.u(11, "DF129 NT"));
  r.skip(2, "DF130 M");
  const bool additional = r.flag("DF131 availability of additional data");
  r.skip(11 + 32, "DF132 NA, DF133 tau c");
  const int n4 = static_cast<int>(r.u(5, "DF134 N4"));
  r.skip(22 + 1, "DF135 tau GPS, DF136 ln");

  g.sat = SatId(System::Glonass, slot);
  if (!g.sat.valid()) throw MessageError("DF038 satellite ID", "GLONASS slot " + std::to_string(slot) + " is not 1-27");
  if (tb < 1 || tb > 96) throw MessageError("DF110 tb", "tb " + std::to_string(tb) + " is not 1-96");
  if (tkH > 23 || tkM > 59) throw MessageError("DF107 tk", "time " + std::to_string(tkH) + ":" + std::to_string(tkM) + " is not a time of day");
  if (fcn <= 13) s.channels.set(slot, fcn - 7);
  const std::optional<int> k = s.channels.get(slot);
  if (!k) throw MessageError("DF040 frequency channel number", "channel number " + std::to_string(fcn) + " is not 0-13 and no channel is known for R" + std::to_string(slot));
  g.frequencyChannel = *k;
  g.health = bn | ln3;
  g.iode = tb;
  // An absolute date when the four-year interval N4 (from 1996) and day NT are given (GLONASS
  // ICD 5.1, 4.5): day NT of the interval starting on 1 January 1996 + 4 (N4 - 1).
  if (additional && n4 >= 1 && nt >= 1 && nt <= 1461) {
    CalendarTime c;
    const std::int64_t days = daysFromCivil(1996 + 4 * (n4 - 1), 1, 1) + (nt - 1);
    civilFromDays(days, c.year, c.month, c.day);
    c.second = tb * 900.0;  // normalised by the conversion
    learnAbsoluteTime(s, glonassToGpst(c));
  }
  g.toe = glonassTodNear(tb * 900.0, s.ref);
  g.tof = glonassTodNear(tkH * 3600.0 + tkM * 60.0 + tkS * 30.0, g.toe);
  ++s.stats.ephemerides;
  s.out.emplace_back(g);
}

}  // namespace gvins::rtcm
