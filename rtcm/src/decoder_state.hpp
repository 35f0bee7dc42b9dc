// Internal state of gvins::rtcm::Decoder, shared by the translation units that decode the
// different message groups. Not installed.
#pragma once

#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include "gvins/rtcm/bit_reader.hpp"
#include "gvins/rtcm/decoder.hpp"
#include "gvins/rtcm/lock_time.hpp"

namespace gvins::rtcm {

/// Per satellite and signal tracking state.
struct SignalTrack {
  GpsTime last;                 ///< time of the last observation
  std::int64_t lockMinMs = 0;   ///< lock-time lower bound at that observation
  bool valid = false;
  // Legacy messages only: accumulated phase-range rollover correction (cycles) and the last raw
  // phase-range minus pseudorange difference (cycles).
  double rolloverCycles = 0.0;
  double lastRawDiffCycles = 0.0;
  bool hasRawDiff = false;
};

struct Decoder::State {
  DecoderOptions opt;
  Framer framer;
  DecoderStats stats;
  std::deque<Decoded> out;
  StationInfo station;
  std::optional<StationPosition> stationPos;
  GlonassChannels channels;
  std::optional<GlonassCodePhaseBiases> biases;

  GpsTime ref;               ///< reference time for resolving times of week/day
  bool refAbsolute = false;  ///< from the options or learned from the stream

  // Epoch assembly.
  std::optional<ObsEpoch> open;
  bool openHasOthers = false;  ///< the open epoch holds non-BeiDou systems
  std::optional<GpsTime> lastClosed;
  bool lastClosedHasOthers = false;
  bool beidouInGpst = false;  ///< the stream was seen stamping BeiDou MSM in GPST
  int openBeidouAsBdt = 0;    ///< BeiDou MSM messages in the open epoch read as BDT

  /// Per satellite (satIndex) the tracks of its signals: a handful each, searched linearly.
  std::vector<std::vector<std::pair<ObsCode, SignalTrack>>> tracks =
      std::vector<std::vector<std::pair<ObsCode, SignalTrack>>>(static_cast<std::size_t>(numSatIndices()));
  /// Last full range (m) per satellite (satIndex) from 1002/1004/1010/1012 and MSM4-7, to
  /// resolve the whole milliseconds that 1001/1003/1009/1011 and MSM1-3 leave out.
  struct RangeTrack {
    GpsTime t;
    double metres = 0.0;
    bool valid = false;
  };
  std::vector<RangeTrack> ranges = std::vector<RangeTrack>(static_cast<std::size_t>(numSatIndices()));

  // The message being decoded (for error reports).
  std::int64_t offset = 0;
  int type = 0;
};

// ---- helpers shared by the decoding units ---------------------------------------------------

/// The track of a satellite's signal (created on first use).
inline SignalTrack& track(Decoder::State& s, SatId sat, ObsCode code) {
  auto& list = s.tracks[static_cast<std::size_t>(satIndex(sat))];
  for (auto& [c, t] : list) {
    if (c == code) return t;
  }
  return list.emplace_back(code, SignalTrack{}).second;
}

/// Loss-of-lock flag (RINEX LLI bit 0) of a signal observed at t with the given lock-time
/// indicator; updates the track.
std::uint8_t lossOfLock(Decoder::State& s, SatId sat, ObsCode code, const GpsTime& t,
                        LockTimeKind kind, int indicator);

/// Records a full (unambiguous) range of a satellite at t.
void noteRange(Decoder::State& s, SatId sat, const GpsTime& t, double metres);
/// A range known modulo `unit` (m) made whole with the satellite's last full range (if within
/// two minutes: ranges change by less than 200 km in that time, far less than the 300 km unit);
/// std::nullopt if there is none.
std::optional<double> resolveRange(const Decoder::State& s, SatId sat, const GpsTime& t, double modulo, double unit);
/// Merges a signal into a satellite's list: a new code is appended, values missing from an
/// existing entry are filled in.
void mergeSignal(SatObs& so, const SignalObs& sig);

/// Time of week (seconds) in GPST resolved near the reference.
GpsTime resolveTow(const Decoder::State& s, double towSeconds);
/// GLONASS time of day (Moscow time, seconds) resolved near the reference.
GpsTime resolveGlonassTimeOfDay(const Decoder::State& s, double todSeconds);
/// BeiDou MSM epoch time read as BDT (already converted to GPST): the GPST-stamping check of the
/// Decoder file comment. `asBdtKept` tells whether the BDT reading was kept.
GpsTime checkBeidouStamp(Decoder::State& s, const GpsTime& asBdt, bool& asBdtKept);
/// Merges the satellites of one observation message into the epoch at t; `more` is the
/// multiple-message / synchronous GNSS flag.
void addObservations(Decoder::State& s, System system, const GpsTime& t, bool more,
                     std::vector<SatObs>& sats, bool beidouAsBdt = false);
/// Moves the reference to an absolute time learned from the stream if the current reference is
/// only the host clock.
void learnAbsoluteTime(Decoder::State& s, const GpsTime& t);

/// Message decoders (the reader is positioned after DF002). Each throws MessageError.
void decodeLegacyGps(Decoder::State& s, BitReader& r, int type);
void decodeLegacyGlonass(Decoder::State& s, BitReader& r, int type);
void decodeMsm(Decoder::State& s, BitReader& r, System system, int msm);
void decodeStationPosition(Decoder::State& s, BitReader& r, int type);
void decodeAntenna(Decoder::State& s, BitReader& r, int type);
void decodeGlonassBiases(Decoder::State& s, BitReader& r);
void decodeGpsEphemeris(Decoder::State& s, BitReader& r);
void decodeGlonassEphemeris(Decoder::State& s, BitReader& r);
void decodeBeidouEphemeris(Decoder::State& s, BitReader& r);
void decodeQzssEphemeris(Decoder::State& s, BitReader& r);
void decodeGalileoEphemeris(Decoder::State& s, BitReader& r, bool inav);
/// SSR messages 1057-1068, 1240-1251, 1258-1263 (decode_ssr.cpp).
void decodeSsr(Decoder::State& s, BitReader& r, int type);

}  // namespace gvins::rtcm
