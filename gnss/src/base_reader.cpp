#include "gvins/gnss/base_reader.hpp"

#include <cmath>
#include <algorithm>
#include <cstring>
#include <span>
#include <filesystem>
#include <fstream>
#include <utility>
#include <variant>
#include <vector>

#include "gvins/base/geodetic.hpp"
#include "gvins/base/local_frame.hpp"
#include "gvins/base/parse_error.hpp"
#include "gvins/base/rinex_obs_reader.hpp"
#include "gvins/rtcm/decoder.hpp"
#include "gvins/ubx/stream_splitter.hpp"
#include "gvins/ubx/ubx_decoder.hpp"

namespace gvins {

namespace {

class RinexBase final : public BaseReader {
 public:
  RinexBase(const std::string& path, bool skip) : reader_(path, options(skip)) {}
  bool next(ObsEpoch& e) override { return reader_.next(e); }
  std::optional<Eigen::Vector3d> antennaPosition() const override {
    const StationInfo& st = reader_.header().station;
    if (!st.approxPosition || st.approxPosition->norm() < 1e6) return std::nullopt;
    const Eigen::Vector3d& m = *st.approxPosition;
    const Eigen::Vector3d& hen = st.antennaDeltaHen;
    if (hen.isZero()) return m;
    // ARP = marker + east/north/up offsets in the marker's local frame (RINEX 3.05, 5.2.4).
    return enuToEcef(Eigen::Vector3d(hen[1], hen[2], hen[0]), m);
  }
  GlonassChannels glonassChannels() const override { return reader_.header().glonassChannels; }
  BaseFormat format() const override { return BaseFormat::Rinex; }
  PhaseAlignments phaseAlignment() const override { return phaseAlignmentOf(reader_.header()); }
  std::string describe() const override {
    char buf[160];
    std::snprintf(buf, sizeof buf, "RINEX %.2f, marker '%s'", reader_.header().version,
                  reader_.header().station.markerName.c_str());
    return buf;
  }
  std::int64_t skipped() const override { return reader_.stats().skippedEpochs; }
  bool mayHaveDoppler() const override {
    for (const auto& list : reader_.header().obsTypes) {
      for (const ObsDescriptor& d : list) {
        if (d.type == ObsType::Doppler) return true;
      }
    }
    return false;
  }
  const RinexObsHeader* rinexHeader() const override { return &reader_.header(); }
  const RinexObsReaderStats* rinexStats() const override { return &reader_.stats(); }

 private:
  static RinexObsReaderOptions options(bool skip) {
    RinexObsReaderOptions o;
    o.skipBadEpochs = skip;
    return o;
  }
  RinexObsReader reader_;
};

class RtcmBase final : public BaseReader {
 public:
  RtcmBase(const std::string& path, const GpsTime& reference, EphemerisStore* nav, bool fromFile = true)
      : nav_(nav), decoder_(options(path, reference)), pushed_(!fromFile) {
    if (fromFile) {
      in_.open(path, std::ios::binary);
      if (!in_) throw ParseError(path, 0, "", "cannot open file");
      buf_.resize(1 << 16);
    }
  }
  void feed(std::span<const std::uint8_t> bytes) override { decoder_.feed(bytes); }
  void finish() override {
    decoder_.finish();
    done_ = true;
  }
  bool next(ObsEpoch& e) override {
    for (;;) {
      while (auto d = decoder_.poll()) {
        if (auto* o = std::get_if<ObsEpoch>(&*d)) {
          e = std::move(*o);
          return true;
        }
        if (nav_) {
          if (auto* k = std::get_if<KeplerEphemeris>(&*d)) nav_->add(*k);
          else if (auto* g = std::get_if<GlonassEphemeris>(&*d)) nav_->add(*g);
          else if (auto* s = std::get_if<SsrMessage>(&*d)) nav_->addSsr(*s);  // SSR mixed into the stream
        }
      }
      if (done_ || pushed_) return false;
      in_.read(reinterpret_cast<char*>(buf_.data()), static_cast<std::streamsize>(buf_.size()));
      const auto n = in_.gcount();
      if (n > 0) decoder_.feed(std::span<const std::uint8_t>(buf_.data(), static_cast<std::size_t>(n)));
      if (n <= 0 || !in_) {
        decoder_.finish();
        done_ = true;
      }
    }
  }
  std::optional<Eigen::Vector3d> antennaPosition() const override {
    const auto& p = decoder_.stationPosition();
    if (!p || p->arp.norm() < 1e6) return std::nullopt;
    return p->arp;
  }
  GlonassChannels glonassChannels() const override { return decoder_.glonassChannels(); }
  BaseFormat format() const override { return BaseFormat::Rtcm; }
  PhaseAlignments phaseAlignment() const override {
    // MSM numbers 1071-1077 (GPS), 1081- (GLONASS), 1091- (Galileo), 1101- (SBAS), 1111- (QZSS),
    // 1121- (BeiDou), 1131- (NavIC): RTCM 10403.3 table 3.5-1.
    static constexpr std::pair<int, System> kMsm[] = {{1070, System::Gps},    {1080, System::Glonass},
                                                      {1090, System::Galileo}, {1100, System::Sbas},
                                                      {1110, System::Qzss},    {1120, System::BeiDou},
                                                      {1130, System::Navic}};
    const auto& m = decoder_.stats().messages;
    auto any = [&](int lo, int hi) {
      for (auto it = m.lower_bound(lo); it != m.end() && it->first <= hi; ++it) {
        if (it->second > 0) return true;
      }
      return false;
    };
    PhaseAlignments a;
    for (const auto& [first, sys] : kMsm) {
      const bool legacy = (sys == System::Gps && any(1001, 1004)) || (sys == System::Glonass && any(1009, 1012));
      if (any(first + 1, first + 7) && !legacy) a.set(sys, PhaseAlignment::Aligned);
    }
    return a;
  }
  std::string describe() const override {
    const auto& s = decoder_.stats();
    char buf[200];
    std::snprintf(buf, sizeof buf, "RTCM 3, %lld frames, %lld CRC failures, %lld epochs",
                  static_cast<long long>(s.framing.frames), static_cast<long long>(s.framing.crcFailures),
                  static_cast<long long>(s.epochs));
    return buf;
  }
  std::int64_t skipped() const override { return decoder_.stats().malformed + decoder_.stats().framing.crcFailures; }
  bool mayHaveDoppler() const override { return true; }

 private:
  static rtcm::DecoderOptions options(const std::string& path, const GpsTime& reference) {
    rtcm::DecoderOptions o;
    if (reference != GpsTime{}) o.referenceTime = reference;  // else the host clock (live streams)
    o.streamName = path;
    return o;
  }
  std::ifstream in_;
  EphemerisStore* nav_;
  rtcm::Decoder decoder_;
  std::vector<std::uint8_t> buf_;
  bool done_ = false;
  bool pushed_;  // bytes come through feed() (live streams), not from the file
};

class UbxBase final : public BaseReader {
 public:
  UbxBase(const std::string& path, EphemerisStore* nav, bool strict, bool fromFile = true)
      : nav_(nav), decoder_(options(path, strict)), pushed_(!fromFile) {
    if (fromFile) {
      in_.open(path, std::ios::binary);
      if (!in_) throw ParseError(path, 0, "", "cannot open file");
      buf_.resize(1 << 16);
    }
  }
  void feed(std::span<const std::uint8_t> bytes) override { decoder_.feed(bytes); }
  void finish() override {
    decoder_.finish();
    done_ = true;
  }
  bool next(ObsEpoch& e) override {
    for (;;) {
      while (auto d = decoder_.poll()) {
        if (auto* o = std::get_if<ObsEpoch>(&*d)) {
          e = std::move(*o);
          return true;
        }
        // Ephemerides assembled from the receiver's own SFRBX subframes.
        if (auto* u = std::get_if<ubx::NavDataUpdate>(&*d); u && nav_) u->addTo(*nav_);
      }
      if (done_ || pushed_) return false;
      in_.read(reinterpret_cast<char*>(buf_.data()), static_cast<std::streamsize>(buf_.size()));
      const auto n = in_.gcount();
      if (n > 0) decoder_.feed(std::span<const std::uint8_t>(buf_.data(), static_cast<std::size_t>(n)));
      if (n <= 0 || !in_) {
        decoder_.finish();
        done_ = true;
      }
    }
  }
  std::optional<Eigen::Vector3d> antennaPosition() const override { return std::nullopt; }
  GlonassChannels glonassChannels() const override { return decoder_.glonassChannels(); }
  BaseFormat format() const override { return BaseFormat::Ubx; }
  // u-blox documents no alignment of the phases of different tracking modes of a band.
  PhaseAlignments phaseAlignment() const override { return {}; }
  std::string describe() const override {
    const auto& s = decoder_.stats();
    char buf[200];
    std::snprintf(buf, sizeof buf, "u-blox UBX, %lld frames, %lld checksum failures, %lld epochs, %lld ephemerides from SFRBX",
                  static_cast<long long>(s.stream.ubxFrames), static_cast<long long>(s.stream.ubxChecksumFailures),
                  static_cast<long long>(s.epochs), static_cast<long long>(s.ephemerides));
    return buf;
  }
  std::int64_t skipped() const override { return decoder_.stats().malformed + decoder_.stats().stream.ubxChecksumFailures; }
  bool mayHaveDoppler() const override { return true; }

 private:
  static ubx::DecoderOptions options(const std::string& path, bool strict) {
    ubx::DecoderOptions o;
    o.streamName = path;
    o.strict = strict;
    return o;
  }
  std::ifstream in_;
  EphemerisStore* nav_;
  ubx::Decoder decoder_;
  std::vector<std::uint8_t> buf_;
  bool done_ = false;
  bool pushed_;  // bytes come through feed() (live streams), not from the file
};

/// Good UBX frames and good RTCM frames in a byte block (mixed streams hold both).
std::pair<int, int> countFrames(std::span<const std::uint8_t> head) {
  ubx::StreamSplitter sp;
  sp.feed(head);
  ubx::StreamFrame f;
  while (sp.next(f)) {
  }
  return {static_cast<int>(sp.stats().ubxFrames), static_cast<int>(sp.stats().rtcmFrames)};
}

}  // namespace

std::optional<BaseFormat> BaseReader::detect(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::vector<unsigned char> head(1 << 16);
  in.read(reinterpret_cast<char*>(head.data()), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  return detectBytes(head);
}

std::optional<BaseFormat> BaseReader::detectBytes(std::span<const std::uint8_t> head) {
  if (head.size() >= 2 && head[0] == 0x1f && head[1] == 0x8b) return BaseFormat::Rinex;
  const std::size_t textHead = std::min<std::size_t>(head.size(), 4096);
  const std::string text(head.begin(), head.begin() + static_cast<std::ptrdiff_t>(textHead));
  if (text.find("RINEX VERSION / TYPE") != std::string::npos) return BaseFormat::Rinex;
  // UBX when its frames (checksums good) are at least as many as the RTCM frames (CRCs good).
  const auto [ubxFrames, rtcmFrames] = countFrames(head);
  if (ubxFrames > 0 && ubxFrames >= rtcmFrames) return BaseFormat::Ubx;
  // An RTCM frame header: 0xD3, six zero bits, a 10-bit length.
  for (std::size_t i = 0; i + 2 < textHead; ++i) {
    if (head[i] == 0xD3 && (head[i + 1] & 0xFC) == 0) return BaseFormat::Rtcm;
  }
  return std::nullopt;
}

std::unique_ptr<BaseReader> BaseReader::open(const std::string& path, const GpsTime& referenceTime,
                                             EphemerisStore* nav, bool skipBadEpochs) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw ParseError(path, 0, "", "is a directory, not an observation file");
  const auto f = detect(path);
  if (!f) {
    std::ifstream probe(path, std::ios::binary);
    if (!probe) throw ParseError(path, 0, "", "cannot open file");
    throw ParseError(path, 1, "format", "neither RINEX observation data nor an RTCM 3 or u-blox UBX stream");
  }
  if (*f == BaseFormat::Rinex) return std::make_unique<RinexBase>(path, skipBadEpochs);
  if (*f == BaseFormat::Ubx) return std::make_unique<UbxBase>(path, nav, !skipBadEpochs);
  return std::make_unique<RtcmBase>(path, referenceTime, nav);
}

std::unique_ptr<BaseReader> BaseReader::openPushed(BaseFormat format, const std::string& name, const GpsTime& referenceTime,
                                                   EphemerisStore* nav, bool skipBadEpochs) {
  if (format == BaseFormat::Ubx) return std::make_unique<UbxBase>(name, nav, !skipBadEpochs, false);
  if (format == BaseFormat::Rtcm) return std::make_unique<RtcmBase>(name, referenceTime, nav, false);
  throw ParseError(name, 0, "format", "RINEX cannot be read from a live stream (UBX or RTCM 3 only)");
}

void BaseReader::feed(std::span<const std::uint8_t>) { throw std::logic_error("BaseReader::feed on a file reader"); }
void BaseReader::finish() {}

}  // namespace gvins
