// Reading receiver observations (the RTK base, and the rover of gvins-spp/gvins-rtk/gvins-replay)
// from a file that is RINEX observation data (2.10-4.0x, plain or gzip), a binary RTCM 3 log
// (legacy 1001-1012 or MSM observations, 1005/1006 station position, ephemerides) or a u-blox UBX
// log (RXM-RAWX observations, RXM-SFRBX ephemerides; NMEA/RTCM mixed in are skipped), detected
// from the content.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include <Eigen/Core>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/observation.hpp"
#include "gvins/base/phase_alignment.hpp"
#include "gvins/base/rinex_obs_header.hpp"
#include "gvins/base/rinex_obs_reader.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"

namespace gvins {

enum class BaseFormat { Rinex, Rtcm, Ubx };

class BaseReader {
 public:
  virtual ~BaseReader() = default;

  /// Opens `path`. `referenceTime` resolves the times of week of an RTCM stream (use the rover's
  /// first epoch; UBX carries full weeks). Ephemerides and SSR corrections an RTCM stream carries,
  /// and the ephemerides and ionosphere parameters assembled from UBX RXM-SFRBX, are added to `nav`
  /// (if not null) as they are decoded. Throws ParseError for unreadable files or a malformed RINEX header;
  /// `skipBadEpochs` as in RinexObsReaderOptions.
  static std::unique_ptr<BaseReader> open(const std::string& path, const GpsTime& referenceTime,
                                          EphemerisStore* nav, bool skipBadEpochs = true);
  /// Detects the format from the first bytes (gzip or "RINEX VERSION / TYPE" text: RINEX; UBX
  /// frames with good checksums, at least as many as RTCM frames with good CRCs: UBX; an RTCM
  /// preamble 0xD3 with a valid frame header: RTCM). nullopt if none.
  static std::optional<BaseFormat> detect(const std::string& path);
  /// The same on the first bytes of a stream (up to 64 KiB are looked at).
  static std::optional<BaseFormat> detectBytes(std::span<const std::uint8_t> head);
  /// A reader of a live UBX or RTCM 3 stream whose bytes the caller pushes with feed() (and
  /// finish() at the end); next() then returns false whenever no complete epoch is decoded yet.
  /// `name` is used in messages. Throws ParseError for BaseFormat::Rinex.
  static std::unique_ptr<BaseReader> openPushed(BaseFormat format, const std::string& name, const GpsTime& referenceTime,
                                                EphemerisStore* nav, bool skipBadEpochs = true);
  /// Pushed readers: bytes of the stream, any chunk size; finish() at its end.
  virtual void feed(std::span<const std::uint8_t> bytes);
  virtual void finish();

  /// Next observation epoch (time order as in the file); false at the end. RINEX format errors
  /// throw ParseError unless skipped.
  virtual bool next(ObsEpoch& epoch) = 0;
  /// Antenna reference point (ECEF, m): the RINEX "APPROX POSITION XYZ" moved by "ANTENNA: DELTA
  /// H/E/N", or the ARP of the latest RTCM 1005/1006 (which may only arrive after some epochs);
  /// nullopt for UBX (the receiver's own NAV-PVT fix is no surveyed position).
  virtual std::optional<Eigen::Vector3d> antennaPosition() const = 0;
  /// GLONASS channels known so far (RINEX header, RTCM 1020/MSM extended information).
  virtual GlonassChannels glonassChannels() const = 0;
  virtual BaseFormat format() const = 0;
  /// What the data state about the alignment of their phases across tracking modes
  /// (base/phase_alignment.hpp): RINEX from the header (phaseAlignmentOf); RTCM per system
  /// Aligned once MSM observations of the system were decoded and no legacy ones (1001-1004,
  /// 1009-1012), which state nothing.
  virtual PhaseAlignments phaseAlignment() const = 0;
  /// One-line description for logs ("RINEX 2.10, marker 3040" / "RTCM 3, 1234 frames, ...").
  virtual std::string describe() const = 0;
  /// Whether Doppler observations may be present (RINEX: a D type in the header; RTCM/UBX: true).
  virtual bool mayHaveDoppler() const = 0;
  /// The RINEX header (first/last epoch, observation types, ignored types), or nullptr for
  /// RTCM and UBX.
  virtual const RinexObsHeader* rinexHeader() const { return nullptr; }
  /// The RINEX reader's counters, or nullptr for RTCM and UBX.
  virtual const RinexObsReaderStats* rinexStats() const { return nullptr; }
  /// Malformed epochs or frames skipped so far.
  virtual std::int64_t skipped() const = 0;
};

}  // namespace gvins
