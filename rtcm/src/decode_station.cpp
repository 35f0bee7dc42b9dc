// Station description messages of RTCM 10403.3 section 3.5: 1005/1006 (stationary antenna
// reference point, DF021-DF028, DF141, DF142, DF364), 1007/1008 (antenna descriptor, DF029-DF033),
// 1033 (receiver and antenna descriptors, DF227-DF232) and 1230 (GLONASS code-phase biases,
// DF421-DF426).
#include <cmath>

#include "decoder_state.hpp"
#include "gvins/base/geodetic.hpp"

namespace gvins::rtcm {
namespace {

std::string readString(BitReader& r, const char* counterField, const char* field) {
  const int n = static_cast<int>(r.u(8, counterField));
  r.need(static_cast<std::size_t>(8 * n), field);
  std::string out;
  out.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) out.push_back(static_cast<char>(r.u(8, field)));
  return out;
}

}  // namespace

void decodeStationPosition(Decoder::State& s, BitReader& r, int type) {
  StationPosition p;
  p.messageType = type;
  p.stationId = static_cast<int>(r.u(12, "DF003 reference station ID"));
  p.itrfYear = static_cast<int>(r.u(6, "DF021 ITRF realization year"));
  p.gps = r.flag("DF022 GPS indicator");
  p.glonass = r.flag("DF023 GLONASS indicator");
  p.galileo = r.flag("DF024 Galileo indicator");
  p.physicalStation = !r.flag("DF141 reference-station indicator");
  p.arp.x() = static_cast<double>(r.s(38, "DF025 antenna reference point ECEF-X")) * 1e-4;
  p.singleOscillator = r.flag("DF142 single receiver oscillator indicator");
  r.skip(1, "DF001 reserved");
  p.arp.y() = static_cast<double>(r.s(38, "DF026 antenna reference point ECEF-Y")) * 1e-4;
  p.quarterCycle = static_cast<int>(r.u(2, "DF364 quarter cycle indicator"));
  p.arp.z() = static_cast<double>(r.s(38, "DF027 antenna reference point ECEF-Z")) * 1e-4;
  if (type == 1006) p.antennaHeight = static_cast<double>(r.u(16, "DF028 antenna height")) * 1e-4;
  if (p.arp.norm() > 1e8) throw MessageError("DF025-DF027 antenna reference point", "position is beyond 100000 km");

  // RINEX convention: APPROX POSITION is the marker, ANTENNA: DELTA H/E/N the ARP above it.
  const double h = p.antennaHeight.value_or(0.0);
  Eigen::Vector3d marker = p.arp;
  if (h != 0.0 && p.arp.norm() > 1e3) {
    const Geodetic g = ecefToGeodetic(p.arp);
    const Eigen::Vector3d up(std::cos(g.lat) * std::cos(g.lon), std::cos(g.lat) * std::sin(g.lon), std::sin(g.lat));
    marker -= h * up;
  }
  s.station.approxPosition = marker;
  s.station.antennaDeltaHen = Eigen::Vector3d(h, 0.0, 0.0);
  s.station.markerNumber = std::to_string(p.stationId);
  s.stationPos = p;
  s.out.emplace_back(p);
}

void decodeAntenna(Decoder::State& s, BitReader& r, int type) {
  AntennaDescriptor a;
  a.messageType = type;
  a.stationId = static_cast<int>(r.u(12, "DF003 reference station ID"));
  a.descriptor = readString(r, "DF029 descriptor counter", "DF030 antenna descriptor");
  a.setupId = static_cast<int>(r.u(8, "DF031 antenna setup ID"));
  if (type == 1008 || type == 1033) a.serial = readString(r, "DF032 serial number counter", "DF033 antenna serial number");
  std::optional<ReceiverDescriptor> rcv;
  if (type == 1033) {
    ReceiverDescriptor d;
    d.stationId = a.stationId;
    d.type = readString(r, "DF227 receiver type counter", "DF228 receiver type descriptor");
    d.firmware = readString(r, "DF229 firmware counter", "DF230 receiver firmware version");
    d.serial = readString(r, "DF231 receiver serial counter", "DF232 receiver serial number");
    rcv = d;
  }
  s.station.antennaType = a.descriptor;
  if (!a.serial.empty()) s.station.antennaNumber = a.serial;
  s.out.emplace_back(a);
  if (rcv) {
    s.station.receiverType = rcv->type;
    s.station.receiverVersion = rcv->firmware;
    s.station.receiverNumber = rcv->serial;
    s.out.emplace_back(*rcv);
  }
}

void decodeGlonassBiases(Decoder::State& s, BitReader& r) {
  GlonassCodePhaseBiases b;
  b.stationId = static_cast<int>(r.u(12, "DF003 reference station ID"));
  b.aligned = r.flag("DF421 GLONASS code-phase bias indicator");
  r.skip(3, "DF001 reserved");
  const int mask = static_cast<int>(r.u(4, "DF422 GLONASS FDMA signals mask"));
  // DF423-DF426 in mask order L1 C/A, L1 P, L2 C/A, L2 P; 0.02 m; 0x8000 = invalid.
  std::optional<double>* fields[4] = {&b.l1ca, &b.l1p, &b.l2ca, &b.l2p};
  static constexpr const char* kNames[4] = {"DF423 L1 C/A code-phase bias", "DF424 L1 P code-phase bias",
                                            "DF425 L2 C/A code-phase bias", "DF426 L2 P code-phase bias"};
  for (int k = 0; k < 4; ++k) {
    if (!((mask >> (3 - k)) & 1)) continue;
    const std::int64_t v = r.s(16, kNames[k]);
    if (v != -32768) *fields[k] = static_cast<double>(v) * 0.02;
  }
  s.biases = b;
  s.out.emplace_back(b);
}

}  // namespace gvins::rtcm
