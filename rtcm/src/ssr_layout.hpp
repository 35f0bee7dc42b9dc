// Layout of the RTCM 3 SSR messages (RTCM 10403.3, section 3.5.12: orbit, clock, code bias,
// combined orbit and clock, URA and high-rate clock messages of GPS 1057-1062, GLONASS 1063-1068,
// Galileo 1240-1245, QZSS 1246-1251 and BeiDou 1258-1263), shared by decode_ssr.cpp and
// encode_ssr.cpp: message numbers, the per-system fields, the DF391 update intervals and the
// code-bias signal and tracking mode identifiers. Not installed.
//
// Header: DF002 message number (12), epoch time 1 s (DF385 GPS / DF458 Galileo / DF460 QZSS:
// seconds of the GPS week, 20 bits; DF465 BeiDou: seconds of the BDT week, 20; DF386 GLONASS:
// seconds of the GLONASS (Moscow) day, 17), DF391 update interval (4), DF388 multiple message
// indicator (1), DF375 satellite reference datum (1, orbit and combined messages only), DF413 IOD
// SSR (4), DF414 SSR provider ID (16), DF415 SSR solution ID (4), DF387 number of satellites (6).
// Per satellite: the satellite ID (DF068 GPS 6 bits, DF384 GLONASS 5, DF252 Galileo 6, DF429 QZSS
// 4, DF488 BeiDou 6; the ID is the satellite number: G01 = 1, J01 = 1 (PRN 193), C01 = 1), then
//   orbit:    issue of data (DF071 GPS IODE 8, DF392 GLONASS IOD 8, DF459 Galileo IODnav 10,
//             DF434 QZSS IODE 8; BeiDou DF470 toe modulo 10 and DF471 IOD 8), DF365 delta radial
//             (22, 0.1 mm), DF366 delta along-track (20, 0.4 mm), DF367 delta cross-track (20,
//             0.4 mm), DF368-DF370 their rates (21 bits 0.001 mm/s, 19 and 19 bits 0.004 mm/s);
//   clock:    DF376 C0 (22, 0.1 mm), DF377 C1 (21, 0.001 mm/s), DF378 C2 (27, 0.00002 mm/s^2);
//   combined: the orbit fields, then the clock fields;
//   bias:     DF379 number of code biases (5), then per bias the signal and tracking mode
//             identifier (DF380 GPS, DF381 GLONASS, DF382 Galileo, DF461 QZSS, DF467 BeiDou; 5
//             bits) and DF383 code bias (14, 0.01 m);
//   URA:      DF389 SSR URA (6);
//   high-rate clock: DF390 (22, 0.1 mm).
// Field widths as published in RTCM 10403.3 and used by BKG's BNC and by pyrtcm. BeiDou names the
// broadcast record by DF470 = (toe mod 8192 s) / 8 s and DF471 = (toe / 720 s) mod 240 (toe in
// seconds of the BDT week; the real 1258 of tests/data/rtcm carries 316 and 230 for toe 338400),
// not by the 24-bit IOD CRC of RTKLIB 2.4.3: the real 1258/1261 messages only parse with 8 bits.
// gvins::SsrOrbitCorrection holds DF470 in issueOfData and DF471 in iodCrc.
#pragma once

#include <array>
#include <cstddef>
#include <optional>

#include "gvins/base/satellite.hpp"
#include "gvins/base/signal.hpp"
#include "gvins/ephemeris/ssr_message.hpp"

namespace gvins::rtcm::ssr {

/// What differs between the systems' SSR messages.
struct SystemLayout {
  System system;
  int orbitType;           ///< message number of the orbit message; the other kinds follow
  int epochBits;           ///< 20 (seconds of week), GLONASS 17 (seconds of day)
  const char* epochField;
  int satBits;
  const char* satField;
  int iodBits;             ///< issue of data of the orbit messages
  const char* iodField;
  int iod2Bits;            ///< BeiDou DF471 IOD; 0 for the other systems
  const char* iod2Field;
  const char* signalField; ///< code-bias signal and tracking mode identifier
};

inline constexpr std::array<SystemLayout, 5> kLayouts{{
    {System::Gps, 1057, 20, "DF385 GPS epoch time 1s", 6, "DF068 GPS satellite ID", 8,
     "DF071 GPS IODE", 0, "", "DF380 GPS signal and tracking mode identifier"},
    {System::Glonass, 1063, 17, "DF386 GLONASS epoch time 1s", 5, "DF384 GLONASS satellite ID", 8,
     "DF392 GLONASS IOD", 0, "", "DF381 GLONASS signal and tracking mode identifier"},
    {System::Galileo, 1240, 20, "DF458 Galileo epoch time 1s", 6, "DF252 Galileo satellite ID", 10,
     "DF459 Galileo IODnav", 0, "", "DF382 Galileo signal and tracking mode identifier"},
    {System::Qzss, 1246, 20, "DF460 QZSS epoch time 1s", 4, "DF429 QZSS satellite ID", 8,
     "DF434 QZSS IODE", 0, "", "DF461 QZSS signal and tracking mode identifier"},
    {System::BeiDou, 1258, 20, "DF465 BeiDou epoch time 1s", 6, "DF488 BeiDou satellite ID", 10,
     "DF470 BeiDou toe modulo", 8, "DF471 BeiDou IOD", "DF467 BeiDou signal and tracking mode identifier"},
}};

/// Message kinds in message-number order (orbit message + 0 ... + 5).
inline constexpr std::array<SsrKind, 6> kKinds{SsrKind::kOrbit,    SsrKind::kClock,
                                               SsrKind::kCodeBias, SsrKind::kCombined,
                                               SsrKind::kUra,      SsrKind::kHighRateClock};

/// The layout of a system's SSR messages; nullptr for systems without them here (SBAS, NavIC).
inline const SystemLayout* layoutOf(System system) {
  for (const SystemLayout& l : kLayouts) {
    if (l.system == system) return &l;
  }
  return nullptr;
}

struct MessageKind {
  const SystemLayout* layout;
  SsrKind kind;
};
/// System and kind of an SSR message number (1057-1068, 1240-1251, 1258-1263).
inline std::optional<MessageKind> messageKind(int type) {
  for (const SystemLayout& l : kLayouts) {
    const int k = type - l.orbitType;
    if (k >= 0 && k < static_cast<int>(kKinds.size())) return MessageKind{&l, kKinds[static_cast<std::size_t>(k)]};
  }
  return std::nullopt;
}
/// Message number of a kind for a system; 0 if none.
inline int messageNumber(System system, SsrKind kind) {
  const SystemLayout* l = layoutOf(system);
  if (!l) return 0;
  for (std::size_t k = 0; k < kKinds.size(); ++k) {
    if (kKinds[k] == kind) return l->orbitType + static_cast<int>(k);
  }
  return 0;
}

inline bool hasOrbit(SsrKind k) { return k == SsrKind::kOrbit || k == SsrKind::kCombined; }
inline bool hasClock(SsrKind k) { return k == SsrKind::kClock || k == SsrKind::kCombined; }

// Field sizes in bits.
inline constexpr int kOrbitBits = 22 + 20 + 20 + 21 + 19 + 19;  // DF365-DF370
inline constexpr int kClockBits = 22 + 21 + 27;                  // DF376-DF378
inline constexpr int kBiasBits = 5 + 14;                         // identifier + DF383
inline constexpr int kUraBits = 6;                               // DF389
inline constexpr int kHighRateClockBits = 22;                    // DF390

// Scale factors (metres, seconds).
inline constexpr double kRadialLsb = 1e-4;      // DF365 0.1 mm
inline constexpr double kAlongCrossLsb = 4e-4;  // DF366, DF367 0.4 mm
inline constexpr double kRadialRateLsb = 1e-6;  // DF368 0.001 mm/s
inline constexpr double kAlongCrossRateLsb = 4e-6;  // DF369, DF370 0.004 mm/s
inline constexpr double kC0Lsb = 1e-4;          // DF376 0.1 mm
inline constexpr double kC1Lsb = 1e-6;          // DF377 0.001 mm/s
inline constexpr double kC2Lsb = 2e-8;          // DF378 0.00002 mm/s^2
inline constexpr double kCodeBiasLsb = 0.01;    // DF383 0.01 m
inline constexpr double kHighRateClockLsb = 1e-4;  // DF390 0.1 mm

// Code-bias signal and tracking mode identifiers 0..31 and their RINEX 3 codes ("" = reserved),
// as RTCM 10403.3 defines them for DF380 (GPS), DF381 (GLONASS), DF382 (Galileo), DF461 (QZSS)
// and DF467 (BeiDou, with the BDS-3 B1C/B2a/B2b identifiers 9-15). These are not the MSM signal
// IDs, and not the IGS-SSR tables either (which RTKLIB's ssr_sig_* arrays hold).
using SignalTable = std::array<const char*, 32>;
// clang-format off
inline constexpr SignalTable kGpsSignals{
    "1C", "1P", "1W", "",   "",   "2C", "2D", "2S", "2L", "2X", "2P", "2W", "",   "",   "5I", "5Q",
    "5X", "1S", "1L", "1X", "",   "",   "",   "",   "",   "",   "",   "",   "",   "",   "",   ""};
inline constexpr SignalTable kGlonassSignals{
    "1C", "1P", "2C", "2P", "",   "",   "",   "",   "",   "",   "",   "",   "",   "",   "",   "",
    "",   "",   "",   "",   "",   "",   "",   "",   "",   "",   "",   "",   "",   "",   "",   ""};
inline constexpr SignalTable kGalileoSignals{
    "1A", "1B", "1C", "1X", "1Z", "5I", "5Q", "5X", "7I", "7Q", "7X", "8I", "8Q", "8X", "6A", "6B",
    "6C", "6X", "6Z", "",   "",   "",   "",   "",   "",   "",   "",   "",   "",   "",   "",   ""};
inline constexpr SignalTable kQzssSignals{
    "1C", "1S", "1L", "2S", "2L", "2X", "5I", "5Q", "5X", "6S", "6L", "6X", "1X", "",   "",   "",
    "",   "",   "",   "",   "",   "",   "",   "",   "",   "",   "",   "",   "",   "",   "",   ""};
inline constexpr SignalTable kBeidouSignals{
    "2I", "2Q", "2X", "6I", "6Q", "6X", "7I", "7Q", "7X", "1D", "1P", "1X", "5D", "5P", "5X", "7D",
    "",   "",   "",   "",   "",   "",   "",   "",   "",   "",   "",   "",   "",   "",   "",   ""};
// clang-format on

inline const SignalTable* signalTable(System system) {
  switch (system) {
    case System::Gps: return &kGpsSignals;
    case System::Glonass: return &kGlonassSignals;
    case System::Galileo: return &kGalileoSignals;
    case System::Qzss: return &kQzssSignals;
    case System::BeiDou: return &kBeidouSignals;
    default: return nullptr;
  }
}

/// RINEX code of a code-bias signal identifier; std::nullopt if reserved.
inline std::optional<ObsCode> signalCode(System system, int identifier) {
  const SignalTable* t = signalTable(system);
  if (!t || identifier < 0 || identifier >= static_cast<int>(t->size())) return std::nullopt;
  const char* c = (*t)[static_cast<std::size_t>(identifier)];
  if (c[0] == '\0') return std::nullopt;
  return ObsCode{c[0], c[1]};
}
/// Inverse: the identifier of a RINEX code; std::nullopt if the message cannot carry it.
inline std::optional<int> signalIdentifier(System system, ObsCode code) {
  const SignalTable* t = signalTable(system);
  if (!t) return std::nullopt;
  for (std::size_t i = 0; i < t->size(); ++i) {
    const char* c = (*t)[i];
    if (c[0] == code.band && c[0] != '\0' && c[1] == code.attr) return static_cast<int>(i);
  }
  return std::nullopt;
}

}  // namespace gvins::rtcm::ssr
