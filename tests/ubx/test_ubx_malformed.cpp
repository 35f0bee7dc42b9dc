// Hand-built messages (u-blox interface description layouts): malformed RAWX (numMeas larger than
// the payload, truncated, bad time), unknown satellites and signals, loss-of-lock logic, NAV and
// ESF decoding, the mixed UBX/RTCM/NMEA splitter, and random bytes (no crash, no hang).
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <numbers>
#include <random>

#include "gvins/base/parse_error.hpp"
#include "gvins/ubx/stream_splitter.hpp"
#include "gvins/ubx/ubx_decoder.hpp"
#include "independent_ubx_scan.hpp"

namespace gvins::ubx {
namespace {

using testing::makeFrame;
using Bytes = std::vector<std::uint8_t>;

void putU(Bytes& b, std::size_t o, std::uint64_t v, int n) {
  for (int i = 0; i < n; ++i) b[o + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(v >> (8 * i));
}

struct Meas {
  double pr = 2.2e7, cp = 1.15e8;
  float dop = -1234.5f;
  std::uint8_t gnss = 0, sv = 5, sig = 0, freq = 0;
  std::uint16_t lock = 5000;
  std::uint8_t cno = 45, cpStd = 1, trk = 0x07;
};

/// RXM-RAWX payload: 16-byte header + 32 bytes per measurement (u-blox F9 HPG 1.32, UBX-RXM-RAWX).
Bytes rawx(double tow, int week, const std::vector<Meas>& ms, std::uint8_t recStat = 1, int numMeas = -1) {
  Bytes p(16 + 32 * ms.size(), 0);
  putU(p, 0, std::bit_cast<std::uint64_t>(tow), 8);
  putU(p, 8, static_cast<std::uint64_t>(week), 2);
  p[10] = 18;
  p[11] = static_cast<std::uint8_t>(numMeas < 0 ? ms.size() : static_cast<std::size_t>(numMeas));
  p[12] = recStat;
  p[13] = 1;
  for (std::size_t i = 0; i < ms.size(); ++i) {
    const std::size_t o = 16 + 32 * i;
    const Meas& m = ms[i];
    putU(p, o, std::bit_cast<std::uint64_t>(m.pr), 8);
    putU(p, o + 8, std::bit_cast<std::uint64_t>(m.cp), 8);
    putU(p, o + 16, std::bit_cast<std::uint32_t>(m.dop), 4);
    p[o + 20] = m.gnss;
    p[o + 21] = m.sv;
    p[o + 22] = m.sig;
    p[o + 23] = m.freq;
    putU(p, o + 24, m.lock, 2);
    p[o + 26] = m.cno;
    p[o + 28] = m.cpStd;
    p[o + 30] = m.trk;
  }
  return p;
}

std::vector<Decoded> decodeAll(Decoder& d, const Bytes& stream) {
  d.feed(stream);
  d.finish();
  std::vector<Decoded> out;
  while (auto x = d.poll()) out.push_back(std::move(*x));
  return out;
}

TEST(UbxMalformed, NumMeasLargerThanPayload) {
  Bytes s = makeFrame(0x02, 0x15, rawx(1000.0, 2300, {Meas{}, Meas{}}, 1, 3));
  const Bytes good = makeFrame(0x02, 0x15, rawx(1001.0, 2300, {Meas{}}));
  const std::size_t goodOffset = s.size();
  s.insert(s.end(), good.begin(), good.end());
  Decoder d;
  const auto out = decodeAll(d, s);
  ASSERT_EQ(out.size(), 1u);  // the bad one skipped, the next decoded
  EXPECT_EQ(std::get<ObsEpoch>(out[0]).time, GpsTime::fromWeekTow(2300, 1001.0));
  EXPECT_EQ(d.stats().malformed, 1);
  ASSERT_EQ(d.stats().issues.size(), 1u);
  EXPECT_EQ(d.stats().issues[0].field, "numMeas");
  EXPECT_EQ(d.stats().issues[0].offset, 0);
  EXPECT_EQ(d.stats().issues[0].type, 0x0215);
  EXPECT_EQ(d.stats().messages.at(0x0215), 2);
  EXPECT_GT(goodOffset, 0u);
  // Strict: a ParseError naming stream, byte offset and field.
  DecoderOptions o;
  o.strict = true;
  o.streamName = "hand.ubx";
  Decoder strict(o);
  try {
    strict.feed(s);
    FAIL() << "no error";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), "hand.ubx");
    EXPECT_EQ(e.line(), 0);
    EXPECT_NE(e.field().find("numMeas"), std::string::npos) << e.field();
  }
}

TEST(UbxMalformed, TruncatedAndImpossibleHeaders) {
  Decoder d;
  Bytes s;
  for (const Bytes& p : {Bytes(10, 0),                                              // shorter than the header
                         rawx(std::nan(""), 2300, {Meas{}}),                        // rcvTow NaN
                         rawx(-5.0, 2300, {Meas{}}), rawx(700000.0, 2300, {Meas{}}),  // not a time of week
                         rawx(10.0, 0, {Meas{}})}) {                                // week unknown
    const Bytes f = makeFrame(0x02, 0x15, p);
    s.insert(s.end(), f.begin(), f.end());
  }
  for (const Bytes& p : {Bytes(50, 0), Bytes(10, 0), Bytes(3, 0)}) {  // NAV-PVT, NAV-CLOCK, ESF-RAW too short
    static int k = 0;
    const std::uint8_t cls = k < 2 ? 0x01 : 0x10, id = k == 0 ? 0x07 : k == 1 ? 0x22 : 0x03;
    ++k;
    const Bytes f = makeFrame(cls, id, p);
    s.insert(s.end(), f.begin(), f.end());
  }
  const auto out = decodeAll(d, s);
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(d.stats().malformed, 8);
  ASSERT_EQ(d.stats().issues.size(), 8u);
  EXPECT_EQ(d.stats().issues[0].field, "leapS");  // the first field past the 10 bytes
  EXPECT_EQ(d.stats().issues[1].field, "rcvTow");
  EXPECT_EQ(d.stats().issues[2].field, "rcvTow");
  EXPECT_EQ(d.stats().issues[3].field, "rcvTow");
  EXPECT_EQ(d.stats().issues[4].field, "week");
  EXPECT_EQ(d.stats().issues[5].field, "NAV-PVT length");
  EXPECT_EQ(d.stats().issues[7].field, "ESF-RAW length");
  // Offsets name each frame's first byte.
  EXPECT_EQ(d.stats().issues[1].offset, 18);
}

TEST(UbxMalformed, UnknownSatellitesAndSignalsAreCounted) {
  Meas imes;
  imes.gnss = 4;  // IMES: no RINEX system
  Meas bad;
  bad.gnss = 9;
  Meas sbasLow;
  sbasLow.gnss = 1;
  sbasLow.sv = 100;  // below PRN 120
  Meas gloUnknownSlot;
  gloUnknownSlot.gnss = 6;
  gloUnknownSlot.sv = 255;
  Meas gpsSig2;
  gpsSig2.sig = 2;  // reserved GPS signal id
  Meas galSig2;
  galSig2.gnss = 2;
  galSig2.sig = 2;
  Meas ok;
  Decoder d;
  const auto out = decodeAll(d, makeFrame(0x02, 0x15, rawx(100.0, 2300, {imes, bad, sbasLow, gloUnknownSlot, gpsSig2, galSig2, ok})));
  ASSERT_EQ(out.size(), 1u);
  const auto& e = std::get<ObsEpoch>(out[0]);
  ASSERT_EQ(e.sats.size(), 1u);
  EXPECT_EQ(e.sats[0].sat, SatId(System::Gps, 5));
  EXPECT_EQ(d.stats().unknownSatellites, 4);
  EXPECT_EQ(d.stats().unknownSignals, 2);
  EXPECT_EQ(d.stats().unknownSignalIds, (std::map<std::pair<int, int>, std::int64_t>{{{0, 2}, 1}, {{2, 2}, 1}}));
  EXPECT_EQ(d.stats().malformed, 0);
}

TEST(UbxMalformed, ValuesFlagsAndSignalMapping) {
  Meas g;  // GPS L1 C/A, all valid
  Meas l5;
  l5.sig = 7;
  l5.trk = 0x01;  // pseudorange only
  Meas r;          // GLONASS R07 L2 OF on channel -3
  r.gnss = 6;
  r.sv = 7;
  r.sig = 2;
  r.freq = 4;
  r.trk = 0x03;  // half cycle not resolved
  Meas c;        // BeiDou C30 B2a pilot
  c.gnss = 3;
  c.sv = 30;
  c.sig = 7;
  Meas s;  // SBAS PRN 131 -> S31
  s.gnss = 1;
  s.sv = 131;
  Meas j;  // QZSS J03 L1C/A
  j.gnss = 5;
  j.sv = 3;
  Decoder d;
  const auto out = decodeAll(d, makeFrame(0x02, 0x15, rawx(345600.25, 2381, {g, l5, r, c, s, j})));
  ASSERT_EQ(out.size(), 1u);
  const auto& e = std::get<ObsEpoch>(out[0]);
  EXPECT_EQ(e.time, GpsTime::fromWeekTow(2381, 345600.25));
  const SignalObs* a = e.find(SatId(System::Gps, 5))->find(ObsCode('1', 'C'));
  ASSERT_TRUE(a);
  EXPECT_EQ(a->pseudorange, 2.2e7);
  EXPECT_EQ(a->carrierPhase, 1.15e8);
  EXPECT_EQ(a->doppler, -1234.5);
  EXPECT_EQ(a->snr, 45);
  EXPECT_EQ(a->lli, 0);  // first epoch, locktime 5000 ms, half cycle resolved
  const SignalObs* b = e.find(SatId(System::Gps, 5))->find(ObsCode('5', 'Q'));
  ASSERT_TRUE(b);
  EXPECT_TRUE(b->hasCode());
  EXPECT_FALSE(b->hasPhase());
  const SignalObs* rr = e.find(SatId(System::Glonass, 7))->find(ObsCode('2', 'C'));
  ASSERT_TRUE(rr);
  EXPECT_EQ(rr->lli, 2);
  EXPECT_EQ(d.glonassChannels().get(7), -3);
  EXPECT_TRUE(e.find(SatId(System::BeiDou, 30))->find(ObsCode('5', 'P')));
  EXPECT_TRUE(e.find(SatId(System::Sbas, 31))->find(ObsCode('1', 'C')));
  EXPECT_TRUE(e.find(SatId(System::Qzss, 3))->find(ObsCode('1', 'C')));
}

TEST(UbxMalformed, LossOfLockFromLocktimeGapsHalfCyclesAndClockResets) {
  auto epoch = [](double tow, std::uint16_t lock, std::uint8_t trk, std::uint8_t rec = 1) {
    Meas m;
    m.lock = lock;
    m.trk = trk;
    return makeFrame(0x02, 0x15, rawx(tow, 2300, {m}, rec));
  };
  Bytes s;
  auto add = [&](const Bytes& f) { s.insert(s.end(), f.begin(), f.end()); };
  add(epoch(100.0, 3000, 0x07));        // 1: first epoch, locked: no flag
  add(epoch(101.0, 4000, 0x07));        // 2: continuous
  add(epoch(102.0, 200, 0x07));         // 3: locktime decreased: slip
  add(epoch(103.0, 1200, 0x07));        // 4: continuous
  add(epoch(103.25, 900, 0x07));        // 4b: locktime decreased, still longer than the gap: slip
  add(epoch(106.0, 2500, 0x07));        // 5: 3 s gap, locktime 2.5 s: re-acquired in the gap
  add(epoch(107.0, 3500, 0x0F));        // 6: half cycle subtracted now: phase jumped half a cycle
  add(epoch(108.0, 4500, 0x0F, 0x03));  // 7: receiver clock reset
  add(epoch(109.0, 5500, 0x0B));        // 8: half cycle no longer valid: bit 1
  Decoder d;
  const auto out = decodeAll(d, s);
  ASSERT_EQ(out.size(), 9u);
  std::vector<int> lli;
  for (const auto& x : out) lli.push_back(std::get<ObsEpoch>(x).sats.at(0).signals.at(0).lli);
  EXPECT_EQ(lli, (std::vector<int>{0, 0, 1, 0, 1, 1, 1, 1, 2}));
  EXPECT_EQ(d.stats().clockResets, 1);
  EXPECT_EQ(d.stats().slips, 5);
}

TEST(UbxMalformed, NavPvtClockAndTimeGps) {
  Bytes pvt(92, 0);
  putU(pvt, 0, 408640000, 4);
  putU(pvt, 4, 2025, 2);
  pvt[6] = 8;
  pvt[7] = 28;
  pvt[8] = 17;
  pvt[9] = 30;
  pvt[10] = 22;
  pvt[11] = 0x07;
  pvt[20] = 3;
  pvt[21] = 0x81;  // gnssFixOK, carrier solution fixed
  pvt[23] = 27;
  putU(pvt, 24, static_cast<std::uint32_t>(-1051471666), 4);  // lon -105.1471666 deg
  putU(pvt, 28, 400966933, 4);                                // lat 40.0966933 deg
  putU(pvt, 32, 1579933, 4);                                  // 1579.933 m
  putU(pvt, 36, 1601321, 4);                                  // hMSL 1601.321 m
  putU(pvt, 48, static_cast<std::uint32_t>(-250), 4);         // velN -0.25 m/s
  putU(pvt, 68, 83, 4);                                       // sAcc 0.083 m/s
  Bytes clk(20, 0);
  putU(clk, 4, static_cast<std::uint32_t>(-123456), 4);  // -123.456 us
  putU(clk, 8, 789, 4);
  Bytes tg(16, 0);
  putU(tg, 8, 2381, 2);
  tg[10] = 18;
  tg[11] = 0x07;
  Bytes s = makeFrame(0x01, 0x07, pvt);
  for (const Bytes& f : {makeFrame(0x01, 0x22, clk), makeFrame(0x01, 0x20, tg)}) s.insert(s.end(), f.begin(), f.end());
  Decoder d;
  const auto out = decodeAll(d, s);
  ASSERT_EQ(out.size(), 3u);
  const auto& p = std::get<NavPvt>(out[0]);
  EXPECT_TRUE(p.fixOk());
  EXPECT_EQ(p.numSv, 27);
  EXPECT_DOUBLE_EQ(p.lonDeg, -105.1471666);
  EXPECT_DOUBLE_EQ(p.latDeg, 40.0966933);
  EXPECT_DOUBLE_EQ(p.height, 1579.933);
  EXPECT_DOUBLE_EQ(p.hMsl, 1601.321);
  EXPECT_DOUBLE_EQ(p.velN, -0.25);
  EXPECT_DOUBLE_EQ(p.sAcc, 0.083);
  EXPECT_EQ(navPvtSolution(p), NavPvtSolution::RtkFixed);
  const auto& c = std::get<NavClock>(out[1]);
  EXPECT_DOUBLE_EQ(c.biasS, -123456e-9);
  EXPECT_DOUBLE_EQ(c.driftSps, 789e-9);
  EXPECT_EQ(std::get<NavTimeGps>(out[2]).week, 2381);
  EXPECT_EQ(d.stats().leapSeconds, 18);
}

std::uint32_t esfWord(int type, std::int32_t value) {
  return (static_cast<std::uint32_t>(type) << 24) | (static_cast<std::uint32_t>(value) & 0xFFFFFFu);
}

TEST(UbxMalformed, EsfRawAndMeasToImuSamples) {
  // ESF-RAW: 4 reserved bytes, then (data, sTtag) pairs; two samples of six axes each. Scale:
  // gyro deg/s * 2^-12, accel m/s^2 * 2^-10 (u-blox ZED-F9R interface description).
  const int types[6] = {14, 13, 5, 16, 17, 18};
  const std::int32_t values[6] = {4096, -8192, 409, 10045, -1024, 1};
  Bytes raw(4 + 8 * 12, 0);
  for (int k = 0; k < 2; ++k) {
    for (int i = 0; i < 6; ++i) {
      const std::size_t o = 4 + 8 * static_cast<std::size_t>(6 * k + i);
      putU(raw, o, esfWord(types[i], values[i] * (k + 1)), 4);
      putU(raw, o + 4, 1000u + 10u * static_cast<unsigned>(k), 4);
    }
  }
  // ESF-MEAS: timeTag, flags (numMeas in bits 11-15), id, data words.
  Bytes meas(8 + 4 * 3, 0);
  putU(meas, 0, 5555, 4);
  putU(meas, 4, 3u << 11, 2);
  putU(meas, 8, esfWord(5, -4096), 4);
  putU(meas, 12, esfWord(18, 10045), 4);
  putU(meas, 16, esfWord(12, 2550), 4);
  Bytes s = makeFrame(0x10, 0x03, raw);
  const Bytes m = makeFrame(0x10, 0x02, meas);
  s.insert(s.end(), m.begin(), m.end());
  Decoder d;
  const auto out = decodeAll(d, s);
  ASSERT_EQ(out.size(), 3u);
  const double deg = std::numbers::pi / 180.0;
  const auto& a = std::get<ImuSample>(out[0]);
  EXPECT_TRUE(a.complete());
  EXPECT_EQ(a.timeTag, 1000u);
  EXPECT_DOUBLE_EQ(a.gyro[0], 1.0 * deg);
  EXPECT_DOUBLE_EQ(a.gyro[1], -2.0 * deg);
  EXPECT_DOUBLE_EQ(a.gyro[2], 409.0 / 4096.0 * deg);
  EXPECT_DOUBLE_EQ(a.accel[0], 10045.0 / 1024.0);
  EXPECT_DOUBLE_EQ(a.accel[1], -1.0);
  const auto& b = std::get<ImuSample>(out[1]);
  EXPECT_EQ(b.timeTag, 1010u);
  EXPECT_DOUBLE_EQ(b.gyro[1], -4.0 * deg);
  const auto& c = std::get<ImuSample>(out[2]);
  EXPECT_EQ(c.timeTag, 5555u);
  EXPECT_FALSE(c.complete());
  EXPECT_DOUBLE_EQ(c.gyro[2], -deg);
  EXPECT_DOUBLE_EQ(c.temperature, 25.5);
  EXPECT_EQ(d.stats().imuSamples, 3);
}

TEST(UbxSplitter, MixedUbxRtcmNmeaStreamAnyChunk) {
  const Bytes rtcm = testing::readBytes(testing::dataDir() / "rtcm/go-gnss_frames/1005_frame.bin");
  const std::string nmea = "$GNGGA,172814.00,4005.80159,N,10508.83000,W,1,12,0.99,1579.9,M,-21.4,M,,*40\r\n";
  const std::string badNmea = "$GNGGA,172814.00,4005.80159,N,10508.83000,W,1,12,0.99,1579.9,M,-21.4,M,,*41\r\n";
  const Bytes ubx = makeFrame(0x02, 0x15, rawx(1.0, 2300, {Meas{}}));
  std::mt19937 rng(3);
  Bytes s;
  std::int64_t nU = 0, nR = 0, nN = 0, nBad = 0;
  for (int k = 0; k < 60; ++k) {
    const int pick = static_cast<int>(rng() % 4);
    if (pick == 0) s.insert(s.end(), ubx.begin(), ubx.end()), ++nU;
    if (pick == 1) s.insert(s.end(), rtcm.begin(), rtcm.end()), ++nR;
    if (pick == 2) s.insert(s.end(), nmea.begin(), nmea.end()), ++nN;
    if (pick == 3) s.insert(s.end(), badNmea.begin(), badNmea.end()), ++nBad;
    if (k % 7 == 0) s.push_back(static_cast<std::uint8_t>(rng()) & 0x7F);  // stray byte
  }
  std::int64_t ubxBytes = 0;
  for (std::size_t chunk : {1u, 3u, 64u, 100000u}) {
    StreamSplitter sp;
    std::int64_t u = 0, r = 0, n = 0, bytes = 0;
    StreamFrame f;
    auto take = [&] {
      bytes += static_cast<std::int64_t>(f.bytes.size());
      if (f.kind == StreamKind::Ubx) {
        ++u;
        EXPECT_EQ(f.ubx().type(), 0x0215);
        ubxBytes = static_cast<std::int64_t>(f.bytes.size());
      } else if (f.kind == StreamKind::Rtcm) {
        ++r;
        EXPECT_EQ(f.bytes.size(), rtcm.size());
      } else {
        ++n;
        EXPECT_EQ(std::string(f.bytes.begin(), f.bytes.end()), nmea);
      }
    };
    for (std::size_t i = 0; i < s.size(); i += chunk) {
      sp.feed({s.data() + i, std::min(chunk, s.size() - i)});
      while (sp.next(f)) take();
    }
    sp.finish();
    while (sp.next(f)) take();
    EXPECT_EQ(u, nU) << chunk;
    EXPECT_EQ(r, nR) << chunk;
    EXPECT_EQ(n, nN) << chunk;
    EXPECT_EQ(sp.stats().nmeaChecksumFailures, nBad) << chunk;
    EXPECT_EQ(bytes + sp.stats().skippedBytes, static_cast<std::int64_t>(s.size()));
  }
  EXPECT_EQ(ubxBytes, static_cast<std::int64_t>(ubx.size()));
}

TEST(UbxMalformed, RandomBytesNeverCrashOrHang) {
  // Random streams rich in sync pairs, frame headers of RAWX with random lengths and RTCM/NMEA
  // starts; valid frames with random payloads (the decoders must reject what does not fit).
  std::mt19937 rng(11);
  for (int trial = 0; trial < 200; ++trial) {
    Bytes s;
    const int n = static_cast<int>(rng() % 3000);
    for (int i = 0; i < n; ++i) {
      switch (rng() % 10) {
        case 0: s.push_back(0xB5); s.push_back(0x62); break;
        case 1: s.push_back(0xD3); break;
        case 2: s.push_back('$'); break;
        case 3: {
          const std::uint8_t ids[][2] = {{0x02, 0x15}, {0x02, 0x13}, {0x01, 0x07}, {0x01, 0x22}, {0x10, 0x02}, {0x10, 0x03}};
          const auto& id = ids[rng() % 6];
          Bytes p(rng() % 120);
          for (auto& b : p) b = static_cast<std::uint8_t>(rng());
          if (id[1] == 0x15 && p.size() > 11) p[11] = static_cast<std::uint8_t>(rng() % 5);
          const Bytes f = makeFrame(id[0], id[1], p);
          s.insert(s.end(), f.begin(), f.end());
          break;
        }
        default: s.push_back(static_cast<std::uint8_t>(rng()));
      }
    }
    Decoder d;
    const std::size_t chunk = 1 + rng() % 200;
    for (std::size_t i = 0; i < s.size(); i += chunk) {
      d.feed({s.data() + i, std::min(chunk, s.size() - i)});
      while (d.poll()) {
      }
    }
    d.finish();
    while (d.poll()) {
    }
    EXPECT_EQ(d.stats().stream.bytes, static_cast<std::int64_t>(s.size()));
  }
}

}  // namespace
}  // namespace gvins::ubx
