#include "gvins/sim/gnss_truth_writer.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "gvins/base/constants.hpp"

namespace gvins::sim {

std::int64_t gpstNanoseconds(const GpsTime& t) {
  return t.wholeSeconds() * 1'000'000'000LL + static_cast<std::int64_t>(std::llround(t.fraction() * 1e9));
}

namespace {

void appendf(std::string& s, const char* fmt, auto... args) {
  char tmp[512];
  const int n = std::snprintf(tmp, sizeof tmp, fmt, args...);
  if (n > 0) s.append(tmp, static_cast<std::size_t>(std::min<int>(n, sizeof tmp - 1)));
}

const char* kClockHeader =
    "# receiver clock truth; tag_ns = RINEX epoch (receiver time), gpst_ns = true GPST = tag - bias\n"
    "tag_ns,gpst_ns,bias_s,drift_sps,bias_G_s,bias_R_s,bias_E_s,bias_C_s,bias_J_s\n";

const char* kErrorHeader =
    "# every term of every measurement (m unless stated): P = range + shapiro + rx_clock + ifb - sat_clock + group_delay"
    " + tropo + iono + mp_code + nlos + code_noise; L*lambda = range + shapiro + rx_clock - sat_clock + tropo - iono"
    " + mp_phase + nlos + phase_noise + (N + windup)*lambda\n"
    "tag_ns,sat,signal,elevation_deg,azimuth_deg,cn0_dbhz,range,range_rate_mps,shapiro,rx_clock,ifb,sat_clock,"
    "sat_clock_error,orbit_error_los,group_delay,tropo,tropo_model,iono,iono_model,mp_code,mp_phase,nlos,code_noise,"
    "phase_noise,doppler_noise_mps,ambiguity_cycles,wavelength,arc_start,lli,windup_cycles\n";

void writeClock(std::string& b, const GnssSimEpoch& e) {
  const auto& t = e.truth;
  appendf(b, "%lld,%lld,%.15e,%.12e", static_cast<long long>(gpstNanoseconds(t.tag)),
          static_cast<long long>(gpstNanoseconds(t.time)), t.clockBias, t.clockDrift);
  for (System s : {System::Gps, System::Glonass, System::Galileo, System::BeiDou, System::Qzss})
    appendf(b, ",%.15e", t.systemClockBias[systemIndex(s)]);
  b += '\n';
}

void writeErrors(std::string& b, const GnssSimEpoch& e) {
  const auto& t = e.truth;
  const long long tag = static_cast<long long>(gpstNanoseconds(t.tag));
  constexpr double c = constants::kSpeedOfLight;
  for (const GnssSatelliteTruth& s : t.sats) {
    const Eigen::Vector3d los = (s.satPosition - t.antennaPosition).normalized();
    const double orbitLos = los.dot(s.orbitError);
    for (const GnssSignalTruth& g : s.signals) {
      appendf(b, "%lld,%s,%s,%.4f,%.4f,%.3f,%.4f,%.5f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,", tag, s.sat.str().c_str(),
              g.code.str().c_str(), s.azel.elevation * constants::kRadToDeg, s.azel.azimuth * constants::kRadToDeg,
              g.cn0, s.range, s.rangeRate, s.shapiro, c * t.systemClockBias[systemIndex(s.sat.system)],
              g.interFrequencyBias, c * s.satClock, c * s.clockError, orbitLos, c * g.groupDelay);
      const double ionoModel = s.ionosphereModelL1 * g.ionosphere / std::max(s.ionosphereL1, 1e-12);
      appendf(b, "%.4f,%.4f,%.4f,%.4f,%.4f,%.5f,%.4f,%.4f,%.5f,%.5f,%lld,%.9f,%d,%d,%.6f\n", s.troposphere,
              s.troposphereModel, g.ionosphere, ionoModel, g.multipathCode, g.multipathPhase, s.nlosBias, g.codeNoise,
              g.phaseNoise, g.dopplerNoise, static_cast<long long>(g.ambiguity), g.wavelength, g.arcStart ? 1 : 0,
              g.lossOfLock ? 1 : 0, s.windup);
    }
  }
}

}  // namespace

std::ofstream GnssTruthWriter::open(const std::string& name) {
  const auto p = dir_ / name;
  std::ofstream f(p, std::ios::binary);
  if (!f) throw std::runtime_error("cannot create " + p.string());
  files_.push_back(p);
  return f;
}

GnssTruthWriter::GnssTruthWriter(const std::filesystem::path& dir, bool withBase, bool errorTerms)
    : dir_(dir), errorTerms_(errorTerms) {
  std::filesystem::create_directories(dir_);
  roverAntenna_ = open("rover_antenna.csv");
  roverAntenna_ << "# rover antenna phase centre (ECEF, m, m/s) at the true time of each GNSS epoch\n"
                   "tag_ns,gpst_ns,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps\n";
  roverClock_ = open("rover_clock.csv");
  roverClock_ << kClockHeader;
  if (withBase) {
    baseClock_ = open("base_clock.csv");
    baseClock_ << kClockHeader;
  }
  if (errorTerms_) {
    roverErrors_ = open("rover_errors.csv");
    roverErrors_ << kErrorHeader;
    if (withBase) {
      baseErrors_ = open("base_errors.csv");
      baseErrors_ << kErrorHeader;
    }
  }
}

void GnssTruthWriter::add(const GnssSimEpoch& e) {
  const bool rover = e.role == GnssReceiverRole::Rover;
  buf_.clear();
  if (rover) {
    const auto& t = e.truth;
    appendf(buf_, "%lld,%lld,%.4f,%.4f,%.4f,%.5f,%.5f,%.5f\n", static_cast<long long>(gpstNanoseconds(t.tag)),
            static_cast<long long>(gpstNanoseconds(t.time)), t.antennaPosition.x(), t.antennaPosition.y(),
            t.antennaPosition.z(), t.antennaVelocity.x(), t.antennaVelocity.y(), t.antennaVelocity.z());
    roverAntenna_ << buf_;
    buf_.clear();
  }
  writeClock(buf_, e);
  (rover ? roverClock_ : baseClock_) << buf_;
  if (errorTerms_) {
    buf_.clear();
    writeErrors(buf_, e);
    (rover ? roverErrors_ : baseErrors_) << buf_;
  }
}

void GnssTruthWriter::finish(const std::vector<GnssAmbiguityArc>& arcs, const std::vector<GnssSlipEvent>& slips,
                             const std::vector<GnssEventInterval>& events) {
  {
    std::ofstream f = open("ambiguities.csv");
    f << "# integer ambiguity N (cycles) of each continuous tracking arc; L = (phase range)/lambda + N\n"
         "receiver,sat,signal,first_tag_ns,last_tag_ns,ambiguity_cycles,wavelength_m,cause\n";
    std::string b;
    for (const GnssAmbiguityArc& a : arcs)
      appendf(b, "%s,%s,%s,%lld,%lld,%lld,%.9f,%s\n", toString(a.role), a.sat.str().c_str(), a.code.str().c_str(),
              static_cast<long long>(gpstNanoseconds(a.firstTag)), static_cast<long long>(gpstNanoseconds(a.lastTag)),
              static_cast<long long>(a.ambiguity), a.wavelength, a.cause.c_str());
    f << b;
  }
  {
    std::ofstream f = open("cycle_slips.csv");
    f << "# ambiguity changes: random slips of a tracked signal and restarts after a loss of lock\n"
         "receiver,tag_ns,sat,signal,jump_cycles,lli_flagged,cause\n";
    std::string b;
    for (const GnssSlipEvent& s : slips)
      appendf(b, "%s,%lld,%s,%s,%lld,%d,%s\n", toString(s.role), static_cast<long long>(gpstNanoseconds(s.tag)),
              s.sat.str().c_str(), s.code.str().c_str(), static_cast<long long>(s.jump), s.flagged ? 1 : 0,
              s.cause.c_str());
    f << b;
  }
  {
    std::ofstream f = open("events.csv");
    f << "# non-line-of-sight reception (value = extra path, m), blockages of single satellites and outages\n"
         "receiver,kind,sat,systems,start_gpst_ns,end_gpst_ns,value\n";
    std::string b;
    for (const GnssEventInterval& e : events)
      appendf(b, "%s,%s,%s,%s,%lld,%lld,%.3f\n", toString(e.role), e.kind.c_str(),
              e.sat.prn ? e.sat.str().c_str() : "", e.systems.c_str(), static_cast<long long>(gpstNanoseconds(e.start)),
              static_cast<long long>(gpstNanoseconds(e.end)), e.value);
    f << b;
  }
  roverAntenna_.flush();
  roverClock_.flush();
  if (baseClock_.is_open()) baseClock_.flush();
  if (roverErrors_.is_open()) roverErrors_.flush();
  if (baseErrors_.is_open()) baseErrors_.flush();
}

}  // namespace gvins::sim
