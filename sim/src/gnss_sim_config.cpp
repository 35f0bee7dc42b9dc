#include "gvins/sim/gnss_sim_config.hpp"

#include <algorithm>
#include <cctype>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "gvins/base/parse_error.hpp"
#include "gvins/base/yaml_reader.hpp"
#include "gvins/ephemeris/ssr_message.hpp"
#include "gvins/rtcm/msm_signals.hpp"

namespace gvins::sim {

bool GnssSimConfig::transmits(SatId sat, ObsCode code) const {
  for (const GnssSignalSatellites& r : signalSatellites) {
    if (r.system != sat.system || !(r.code == code)) continue;
    return std::find(r.prns.begin(), r.prns.end(), sat.prn) != r.prns.end();
  }
  return true;
}

double GnssSimConfig::cn0Offset(System s, ObsCode code) const {
  for (const auto& [key, v] : cn0Offsets)
    if (key.first == s && key.second == code) return v;
  return 0.0;
}

double GnssSimConfig::codeNoiseFactor(System s, ObsCode code) const {
  for (const auto& [key, v] : codeNoiseFactors)
    if (key.first == s && key.second == code) return v;
  return 1.0;
}

GnssReceiverConfig GnssSimConfig::defaultRover() {
  GnssReceiverConfig r;
  r.rate = 10.0;
  r.elevationMaskDeg = 5.0;
  r.cn0.zenith = 46.0;  // small patch antenna on a UAV: a few dB below a geodetic antenna
  r.cn0.horizon = 32.0;
  r.multipath = {0.2, 0.002, 5.0};
  r.nlos = {0.2, 40.0, 4.0, 10.0, 50.0, 10.0};
  r.blockage = {0.05, 90.0, 5.0};
  r.slips = {0.01, 10, 0.8};
  r.markerName = "ROVER";
  return r;
}

GnssBaseConfig GnssSimConfig::defaultBase() {
  GnssBaseConfig b;
  b.receiver.rate = 1.0;
  b.receiver.elevationMaskDeg = 5.0;
  b.receiver.cn0.zenith = 50.0;
  b.receiver.cn0.horizon = 36.0;
  b.receiver.multipath = {0.1, 0.001, 60.0};
  b.receiver.markerName = "BASE";
  return b;
}

namespace {

class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const YAML::Node& n, const std::string& key, const std::string& what) const {
    const auto m = n.Mark();
    throw ParseError(file_, m.line >= 0 ? m.line + 1 : 0, key, what);
  }
  template <class T>
  T get(const YAML::Node& n, const std::string& key) const {
    try {
      return n.as<T>();
    } catch (const YAML::Exception&) {
      fail(n, key, "wrong type for '" + key + "'");
    }
  }
  double number(const YAML::Node& n, const std::string& key, double lo, double hi) const {
    if (!n.IsScalar()) fail(n, key, "'" + key + "' must be a number");
    const double v = get<double>(n, key);
    if (!(v >= lo && v <= hi)) {
      std::ostringstream os;
      os << "'" << key << "' = " << v << " is outside [" << lo << ", " << hi << "]";
      fail(n, key, os.str());
    }
    return v;
  }
  int integer(const YAML::Node& n, const std::string& key, int lo, int hi) const {
    if (!n.IsScalar()) fail(n, key, "'" + key + "' must be an integer");
    const int v = get<int>(n, key);
    if (v < lo || v > hi) {
      fail(n, key, "'" + key + "' = " + std::to_string(v) + " is outside [" + std::to_string(lo) + ", " +
                       std::to_string(hi) + "]");
    }
    return v;
  }
  bool boolean(const YAML::Node& n, const std::string& key) const {
    if (!n.IsScalar()) fail(n, key, "'" + key + "' must be true or false");
    return get<bool>(n, key);
  }
  std::string text(const YAML::Node& n, const std::string& key) const {
    if (!n.IsScalar()) fail(n, key, "'" + key + "' must be a string");
    return get<std::string>(n, key);
  }
  template <class F>
  void map(const YAML::Node& n, const std::string& where, const std::set<std::string>& known, F&& f) const {
    if (!n.IsMap()) fail(n, where, "'" + where + "' must be a map");
    for (auto it = n.begin(); it != n.end(); ++it) {
      if (!it->first.IsScalar()) fail(it->first, where, "keys of '" + where + "' must be plain names");
      const std::string k = it->first.Scalar();
      const std::string full = where + "." + k;
      if (!known.count(k)) fail(it->first, full, "unknown key '" + full + "'");
      f(k, full, it->second);
    }
  }
  template <class F>
  void sequence(const YAML::Node& n, const std::string& where, F&& f) const {
    if (!n.IsSequence()) fail(n, where, "'" + where + "' must be a list");
    std::size_t i = 0;
    for (auto it = n.begin(); it != n.end(); ++it, ++i) f(where + "[" + std::to_string(i) + "]", *it);
  }
  /// Map keyed by system letter.
  template <class F>
  void perSystem(const YAML::Node& n, const std::string& where, F&& f) const {
    if (!n.IsMap()) fail(n, where, "'" + where + "' must be a map of system letters");
    for (auto it = n.begin(); it != n.end(); ++it) {
      if (!it->first.IsScalar()) fail(it->first, where, "keys of '" + where + "' must be system letters");
      const std::string k = it->first.Scalar();
      const auto s = k.size() == 1 ? systemFromLetter(k[0]) : std::nullopt;
      if (!s) fail(it->first, where + "." + k, "unknown system '" + k + "' (use G R E C J S I)");
      f(*s, where + "." + k, it->second);
    }
  }
  std::array<bool, kNumSystems> systems(const YAML::Node& n, const std::string& key) const {
    std::array<bool, kNumSystems> out{};
    const std::string t = text(n, key);
    for (char c : t) {
      if (c == ',' || c == ' ') continue;
      const auto s = systemFromLetter(static_cast<char>(std::toupper(static_cast<unsigned char>(c))));
      if (!s) fail(n, key, std::string("unknown system letter '") + c + "' (use G R E C J S I)");
      out[systemIndex(*s)] = true;
    }
    if (std::none_of(out.begin(), out.end(), [](bool b) { return b; })) fail(n, key, "'" + key + "' names no system");
    return out;
  }
  /// A signal code of a system ("1C"), checked against the system's bands.
  ObsCode code(System s, const YAML::Node& n, const std::string& key) const {
    const std::string t = text(n, key);
    const auto c = ObsCode::parse(t);
    if (!c || t.size() != 2) fail(n, key, "'" + t + "' is not a RINEX 3 signal code such as 1C");
    const bool band = s == System::Glonass ? (c->band == '1' || c->band == '2') : isKnownBand(s, c->band);
    if (!band || (s != System::Glonass && !carrierFrequency(s, c->band)))
      fail(n, key, "band " + std::string(1, c->band) + " does not exist for " + std::string(systemName(s)));
    // Only signals a real receiver reports (those with an RTCM MSM signal ID, RTCM 10403.3
    // tables 3.5-91 to 3.5-108), so every simulated signal also goes into the base's RTCM stream.
    if (!rtcm::msmSignalId(s, *c)) fail(n, key, t + " is not a signal of " + std::string(systemName(s)));
    return *c;
  }
  template <class F>
  void perSignal(const YAML::Node& n, const std::string& where, F&& f) const {
    if (!n.IsMap()) fail(n, where, "'" + where + "' must be a map of signals (G2W: ...)");
    for (auto it = n.begin(); it != n.end(); ++it) {
      if (!it->first.IsScalar()) fail(it->first, where, "keys of '" + where + "' must be signals such as G2W");
      const std::string full = where + "." + it->first.Scalar();
      const std::string t = it->first.Scalar();
      const auto s = t.size() == 3 ? systemFromLetter(t[0]) : std::nullopt;
      if (!s) fail(it->first, full, "'" + t + "' is not a system letter and signal code such as G2W");
      const auto c = ObsCode::parse(t.substr(1));
      if (!c || !rtcm::msmSignalId(*s, *c)) fail(it->first, full, "'" + t + "' is not a signal of " + std::string(systemName(*s)));
      f(*s, *c, full, it->second);
    }
  }

 private:
  std::string file_;
};

void applyField(const Reader& r, const YAML::Node& n, const std::string& where, GnssRandomFieldConfig& f,
                const std::string& sigmaKey, double sigmaMax) {
  r.map(n, where, {sigmaKey, "correlation_km", "covariance", "speed_mps"},
        [&](const std::string& k, const std::string& full, const YAML::Node& v) {
          if (k == sigmaKey) f.sigma = r.number(v, full, 0.0, sigmaMax);
          else if (k == "correlation_km") f.correlationLength = r.number(v, full, 0.01, 1e5) * 1e3;
          else if (k == "speed_mps") f.speed = r.number(v, full, 0.0, 1e4);
          else {
            const std::string t = r.text(v, full);
            if (t == "gaussian") f.covariance = GnssRandomFieldConfig::Covariance::Gaussian;
            else if (t == "exponential") f.covariance = GnssRandomFieldConfig::Covariance::Exponential;
            else r.fail(v, full, "'" + full + "' must be gaussian or exponential, not '" + t + "'");
          }
        });
}

std::vector<GnssRandomFieldConfig> fields(const Reader& r, const YAML::Node& n, const std::string& where,
                                          const std::string& sigmaKey, double sigmaMax) {
  std::vector<GnssRandomFieldConfig> out;
  r.sequence(n, where, [&](const std::string& item, const YAML::Node& v) {
    GnssRandomFieldConfig f;
    applyField(r, v, item, f, sigmaKey, sigmaMax);
    out.push_back(f);
  });
  if (out.size() > 8) r.fail(n, where, "at most 8 residual fields");
  return out;
}

void applyReceiver(const Reader& r, const std::string& k, const std::string& full, const YAML::Node& v,
                   GnssReceiverConfig& c) {
  if (k == "rate_hz") {
    c.rate = r.number(v, full, 0.01, 100.0);
  } else if (k == "elevation_mask_deg") {
    c.elevationMaskDeg = r.number(v, full, -5.0, 60.0);
  } else if (k == "clock") {
    r.map(v, full,
          {"h0", "h_minus2", "initial_bias_max_s", "initial_drift_sigma", "isb_sigma_ns",
           "glonass_ifb_m_per_channel", "report_offset", "report_sigma_ns"},
          [&](const std::string& ck, const std::string& cf, const YAML::Node& cv) {
            auto& cl = c.clock;
            if (ck == "h0") cl.h0 = r.number(cv, cf, 0.0, 1e-15);
            else if (ck == "h_minus2") cl.hMinus2 = r.number(cv, cf, 0.0, 1e-15);
            else if (ck == "initial_bias_max_s") cl.initialBiasMax = r.number(cv, cf, 0.0, 1e-2);
            else if (ck == "initial_drift_sigma") cl.initialDriftSigma = r.number(cv, cf, 0.0, 1e-5);
            else if (ck == "glonass_ifb_m_per_channel") cl.glonassIfbPerChannel = r.number(cv, cf, -100.0, 100.0);
            else if (ck == "report_offset") cl.reportOffset = r.boolean(cv, cf);
            else if (ck == "report_sigma_ns") cl.reportSigma = r.number(cv, cf, 0.0, 1e6) * 1e-9;
            else
              r.perSystem(cv, cf, [&](System s, const std::string& sf, const YAML::Node& sv) {
                cl.isbSigma[systemIndex(s)] = r.number(sv, sf, 0.0, 1e6) * 1e-9;
              });
          });
  } else if (k == "cn0") {
    r.map(v, full, {"zenith_dbhz", "horizon_dbhz", "satellite_sigma_db", "noise_db", "minimum_dbhz"},
          [&](const std::string& ck, const std::string& cf, const YAML::Node& cv) {
            if (ck == "zenith_dbhz") c.cn0.zenith = r.number(cv, cf, 10.0, 70.0);
            else if (ck == "horizon_dbhz") c.cn0.horizon = r.number(cv, cf, 0.0, 70.0);
            else if (ck == "satellite_sigma_db") c.cn0.satelliteSigma = r.number(cv, cf, 0.0, 20.0);
            else if (ck == "noise_db") c.cn0.noise = r.number(cv, cf, 0.0, 20.0);
            else c.cn0.minimum = r.number(cv, cf, 0.0, 60.0);
          });
    if (c.cn0.horizon > c.cn0.zenith) r.fail(v, full, "cn0.horizon_dbhz must not exceed cn0.zenith_dbhz");
  } else if (k == "noise") {
    r.map(v, full, {"code_m", "phase_cycles", "doppler_mps"},
          [&](const std::string& nk, const std::string& nf, const YAML::Node& nv) {
            if (nk == "code_m") c.noise.code = r.number(nv, nf, 0.0, 100.0);
            else if (nk == "phase_cycles") c.noise.phase = r.number(nv, nf, 0.0, 0.25);
            else c.noise.doppler = r.number(nv, nf, 0.0, 100.0);
          });
  } else if (k == "multipath") {
    r.map(v, full, {"code_m", "phase_m", "time_constant_s"},
          [&](const std::string& mk, const std::string& mf, const YAML::Node& mv) {
            if (mk == "code_m") c.multipath.code = r.number(mv, mf, 0.0, 100.0);
            else if (mk == "phase_m") c.multipath.phase = r.number(mv, mf, 0.0, 0.05);
            else c.multipath.timeConstant = r.number(mv, mf, 0.01, 1e5);
          });
  } else if (k == "nlos") {
    r.map(v, full, {"rate_per_min", "max_elevation_deg", "mean_duration_s", "bias_min_m", "bias_max_m", "cn0_drop_db"},
          [&](const std::string& nk, const std::string& nf, const YAML::Node& nv) {
            auto& n = c.nlos;
            if (nk == "rate_per_min") n.ratePerMinute = r.number(nv, nf, 0.0, 60.0);
            else if (nk == "max_elevation_deg") n.maxElevationDeg = r.number(nv, nf, 0.0, 90.0);
            else if (nk == "mean_duration_s") n.meanDuration = r.number(nv, nf, 0.01, 3600.0);
            else if (nk == "bias_min_m") n.biasMin = r.number(nv, nf, 0.0, 1000.0);
            else if (nk == "bias_max_m") n.biasMax = r.number(nv, nf, 0.0, 1000.0);
            else n.cn0Drop = r.number(nv, nf, 0.0, 40.0);
          });
    if (c.nlos.biasMax < c.nlos.biasMin) r.fail(v, full, "nlos.bias_max_m must not be below nlos.bias_min_m");
  } else if (k == "blockage") {
    r.map(v, full, {"rate_per_min", "max_elevation_deg", "mean_duration_s"},
          [&](const std::string& bk, const std::string& bf, const YAML::Node& bv) {
            if (bk == "rate_per_min") c.blockage.ratePerMinute = r.number(bv, bf, 0.0, 60.0);
            else if (bk == "max_elevation_deg") c.blockage.maxElevationDeg = r.number(bv, bf, 0.0, 90.0);
            else c.blockage.meanDuration = r.number(bv, bf, 0.01, 3600.0);
          });
  } else if (k == "cycle_slips") {
    r.map(v, full, {"rate_per_min", "max_cycles", "flagged_fraction"},
          [&](const std::string& sk, const std::string& sf, const YAML::Node& sv) {
            if (sk == "rate_per_min") c.slips.ratePerMinute = r.number(sv, sf, 0.0, 60.0);
            else if (sk == "max_cycles") c.slips.maxCycles = r.integer(sv, sf, 1, 1000000);
            else c.slips.flaggedFraction = r.number(sv, sf, 0.0, 1.0);
          });
  } else if (k == "outages") {
    c.outages.clear();
    r.sequence(v, full, [&](const std::string& item, const YAML::Node& ov) {
      GnssOutage o;
      bool haveStart = false, haveDuration = false;
      r.map(ov, item, {"start_s", "duration_s", "systems"},
            [&](const std::string& ok, const std::string& of, const YAML::Node& x) {
              if (ok == "start_s") {
                o.start = r.number(x, of, 0.0, 1e7);
                haveStart = true;
              } else if (ok == "duration_s") {
                o.duration = r.number(x, of, 0.0, 1e7);
                haveDuration = true;
              } else {
                o.systems = r.systems(x, of);
              }
            });
      if (!haveStart || !haveDuration) r.fail(ov, item, "'" + item + "' needs start_s and duration_s");
      c.outages.push_back(o);
    });
  } else if (k == "marker") {
    c.markerName = r.text(v, full).substr(0, 60);
  } else if (k == "receiver_type") {
    c.receiverType = r.text(v, full).substr(0, 20);
  } else if (k == "antenna_type") {
    c.antennaType = r.text(v, full).substr(0, 20);
  }
}

const std::set<std::string> kReceiverKeys = {"rate_hz", "elevation_mask_deg", "clock", "cn0", "noise",
                                             "multipath", "nlos", "blockage", "cycle_slips", "outages",
                                             "marker", "receiver_type", "antenna_type"};

/// gnss.signals: up to 4 signals per system, one per band.
void applySignals(const Reader& r, const YAML::Node& v, const std::string& full, GnssSimConfig& c) {
  r.perSystem(v, full, [&](System s, const std::string& sf, const YAML::Node& sv) {
    std::vector<ObsCode> codes;
    r.sequence(sv, sf, [&](const std::string& item, const YAML::Node& cv) {
      const ObsCode oc = r.code(s, cv, item);
      if (std::find(codes.begin(), codes.end(), oc) != codes.end()) r.fail(cv, item, "signal " + oc.str() + " listed twice");
      for (const ObsCode& o : codes)
        if (o.band == oc.band) r.fail(cv, item, "two signals on band " + std::string(1, oc.band) + " (one per band)");
      codes.push_back(oc);
    });
    if (codes.size() > 4) r.fail(sv, sf, "at most 4 signals per system");
    c.signals[systemIndex(s)] = codes;
  });
}

/// gnss.satellite_errors: broadcast record blending and per-system SISRE.
void applySatelliteErrors(const Reader& r, const YAML::Node& v, const std::string& full, GnssSimConfig& c) {
  r.map(v, full, {"blend_records", "sisre_m"}, [&](const std::string& sk, const std::string& sf, const YAML::Node& sv) {
    if (sk == "blend_records") {
      c.satelliteErrors.blendRecords = r.boolean(sv, sf);
    } else {
      r.perSystem(sv, sf, [&](System s, const std::string& xf, const YAML::Node& xv) {
        c.satelliteErrors.sisre[systemIndex(s)] = r.number(xv, xf, 0.0, 100.0);
      });
    }
  });
}

/// gnss.precise_products: the precise orbit/clock files and the SSR stream.
void applyPreciseProducts(const Reader& r, const YAML::Node& v, const std::string& full, GnssSimConfig& c) {
  r.map(v, full, {"write", "orbit_interval_s", "clock_interval_s", "sisre_m", "centre_of_mass", "ssr_interval_s"},
        [&](const std::string& pk, const std::string& pf, const YAML::Node& pv) {
          auto& p = c.preciseProducts;
          if (pk == "write") {
            p.write = r.boolean(pv, pf);
          } else if (pk == "centre_of_mass") {
            p.centreOfMass = r.boolean(pv, pf);
          } else if (pk == "orbit_interval_s") {
            p.orbitInterval = r.number(pv, pf, 1.0, 3600.0);
          } else if (pk == "clock_interval_s") {
            p.clockInterval = r.number(pv, pf, 1.0, 3600.0);
          } else if (pk == "ssr_interval_s") {
            // DF391 update intervals (RTCM 10403.3), 0 = no SSR stream.
            const double interval = r.number(pv, pf, 0.0, 10800.0);
            if (interval != 0.0 && !isSsrUpdateInterval(interval))
              r.fail(pv, pf,
                     "'" + pf + "' must be 0 or an RTCM SSR update interval (1, 2, 5, 10, 15, 30, 60, 120, 240, "
                     "300, 600, 900, 1800, 3600, 7200 or 10800 s)");
            p.ssrInterval = interval;
          } else {
            r.perSystem(pv, pf, [&](System s, const std::string& xf, const YAML::Node& xv) {
              p.sisre[systemIndex(s)] = r.number(xv, xf, 0.0, 100.0);
            });
          }
        });
}

/// gnss.troposphere: the true troposphere's deviations from the model.
void applyTroposphere(const Reader& r, const YAML::Node& v, const std::string& full, GnssSimConfig& c) {
  r.map(v, full,
        {"relative_humidity", "hydrostatic_scale_sigma", "wet_scale_sigma", "layer_height_m", "residual"},
        [&](const std::string& tk, const std::string& tf, const YAML::Node& tv) {
          auto& t = c.troposphere;
          if (tk == "relative_humidity") t.relativeHumidity = r.number(tv, tf, 0.0, 1.0);
          else if (tk == "hydrostatic_scale_sigma") t.hydrostaticScaleSigma = r.number(tv, tf, 0.0, 0.5);
          else if (tk == "wet_scale_sigma") t.wetScaleSigma = r.number(tv, tf, 0.0, 2.0);
          else if (tk == "layer_height_m") t.layerHeight = r.number(tv, tf, 1.0, 20000.0);
          else t.residual = fields(r, tv, tf, "sigma_m", 2.0);
        });
}

/// gnss.ionosphere: the true ionosphere's deviations from the model.
void applyIonosphere(const Reader& r, const YAML::Node& v, const std::string& full, GnssSimConfig& c) {
  r.map(v, full, {"model_scale_sigma", "shell_height_km", "residual"},
        [&](const std::string& ik, const std::string& iff, const YAML::Node& iv) {
          auto& i = c.ionosphere;
          if (ik == "model_scale_sigma") i.modelScaleSigma = r.number(iv, iff, 0.0, 2.0);
          else if (ik == "shell_height_km") i.shellHeight = r.number(iv, iff, 50.0, 2000.0) * 1e3;
          else i.residual = fields(r, iv, iff, "sigma_tecu", 200.0);
        });
}

/// gnss.base: the base station's place and receiver.
void applyBase(const Reader& r, const YAML::Node& v, const std::string& full, GnssSimConfig& c) {
  std::set<std::string> keys = kReceiverKeys;
  keys.insert({"enabled", "distance_m", "azimuth_deg", "height_m", "position_llh"});
  r.map(v, full, keys, [&](const std::string& bk, const std::string& bf, const YAML::Node& bv) {
    auto& b = c.base;
    if (bk == "enabled") {
      b.enabled = r.boolean(bv, bf);
    } else if (bk == "distance_m") {
      b.distance = r.number(bv, bf, 0.0, 1e6);
    } else if (bk == "azimuth_deg") {
      b.azimuthDeg = r.number(bv, bf, -360.0, 360.0);
    } else if (bk == "height_m") {
      b.height = r.number(bv, bf, -1000.0, 10000.0);
    } else if (bk == "position_llh") {
      if (!bv.IsSequence() || bv.size() != 3) r.fail(bv, bf, "'" + bf + "' must be [lat_deg, lon_deg, height_m]");
      b.positionLlh = Eigen::Vector3d(r.number(bv[0], bf, -90.0, 90.0), r.number(bv[1], bf, -180.0, 360.0),
                                      r.number(bv[2], bf, -1000.0, 1e5));
    } else {
      applyReceiver(r, bk, bf, bv, b.receiver);
    }
  });
}

/// gnss.rtcm: the base station's RTCM 3 stream.
void applyRtcm(const Reader& r, const YAML::Node& v, const std::string& full, GnssSimConfig& c) {
  r.map(v, full, {"msm", "station_id", "station_interval_s", "antenna_height_m", "ephemeris_interval_s"},
        [&](const std::string& rk, const std::string& rf, const YAML::Node& rv) {
          auto& t = c.rtcm;
          if (rk == "msm") {
            t.msm = r.integer(rv, rf, 4, 7);
            if (t.msm != 4 && t.msm != 7) r.fail(rv, rf, "'" + rf + "' must be 4 or 7");
          } else if (rk == "station_id") {
            t.stationId = r.integer(rv, rf, 0, 4095);
          } else if (rk == "station_interval_s") {
            t.stationInterval = r.number(rv, rf, 0.1, 3600.0);
          } else if (rk == "antenna_height_m") {
            t.antennaHeight = r.number(rv, rf, 0.0, 6.5535);
          } else {
            t.ephemerisInterval = r.number(rv, rf, 1.0, 7200.0);
          }
        });
}

void apply(const Reader& r, const YAML::Node& g, const std::string& file, GnssSimConfig& c) {
  static const std::set<std::string> kKeys = {
      "navigation", "systems",     "signals",     "signal_satellites", "cn0_offset_db", "code_noise_factor",
      "include_unhealthy", "satellite_errors", "precise_products", "troposphere", "ionosphere", "shapiro", "phase_windup", "rover", "base",
      "rtcm",       "error_terms"};
  r.map(g, "gnss", kKeys, [&](const std::string& k, const std::string& full, const YAML::Node& v) {
    if (k == "navigation") {
      const std::string t = r.text(v, full);
      if (t.empty()) r.fail(v, full, "'" + full + "' is empty");
      std::filesystem::path p(t);
      if (p.is_relative() && !file.empty()) p = std::filesystem::path(file).parent_path() / p;
      c.navigationFile = p.lexically_normal();
    } else if (k == "systems") {
      c.systems = r.systems(v, full);
    } else if (k == "signals") {
      applySignals(r, v, full, c);
    } else if (k == "signal_satellites") {
      r.perSignal(v, full, [&](System s, ObsCode oc, const std::string& sf, const YAML::Node& sv) {
        GnssSignalSatellites rule{s, oc, {}};
        r.sequence(sv, sf, [&](const std::string& item, const YAML::Node& pv) {
          rule.prns.push_back(static_cast<std::uint8_t>(r.integer(pv, item, minPrn(s), maxPrn(s))));
        });
        std::erase_if(c.signalSatellites, [&](const GnssSignalSatellites& x) { return x.system == s && x.code == oc; });
        c.signalSatellites.push_back(rule);
      });
    } else if (k == "cn0_offset_db") {
      r.perSignal(v, full, [&](System s, ObsCode oc, const std::string& sf, const YAML::Node& sv) {
        std::erase_if(c.cn0Offsets, [&](const auto& x) { return x.first.first == s && x.first.second == oc; });
        c.cn0Offsets.push_back({{s, oc}, r.number(sv, sf, -30.0, 30.0)});
      });
    } else if (k == "code_noise_factor") {
      r.perSignal(v, full, [&](System s, ObsCode oc, const std::string& sf, const YAML::Node& sv) {
        std::erase_if(c.codeNoiseFactors, [&](const auto& x) { return x.first.first == s && x.first.second == oc; });
        c.codeNoiseFactors.push_back({{s, oc}, r.number(sv, sf, 0.0, 100.0)});
      });
    } else if (k == "include_unhealthy") {
      c.includeUnhealthy = r.boolean(v, full);
    } else if (k == "satellite_errors") {
      applySatelliteErrors(r, v, full, c);
    } else if (k == "precise_products") {
      applyPreciseProducts(r, v, full, c);
    } else if (k == "troposphere") {
      applyTroposphere(r, v, full, c);
    } else if (k == "ionosphere") {
      applyIonosphere(r, v, full, c);
    } else if (k == "shapiro") {
      c.shapiroDelay = r.boolean(v, full);
    } else if (k == "phase_windup") {
      c.phaseWindup = r.boolean(v, full);
    } else if (k == "rover") {
      r.map(v, full, kReceiverKeys, [&](const std::string& rk, const std::string& rf, const YAML::Node& rv) {
        applyReceiver(r, rk, rf, rv, c.rover);
      });
    } else if (k == "base") {
      applyBase(r, v, full, c);
    } else if (k == "rtcm") {
      applyRtcm(r, v, full, c);
    } else if (k == "error_terms") {
      c.writeErrorTerms = r.boolean(v, full);
    }
  });
}

}  // namespace

GnssSimConfig parseGnssSimConfig(const YAML::Node& gnssSection, const std::string& file) {
  GnssSimConfig c;
  const Reader r(file);
  if (!gnssSection || gnssSection.IsNull()) return c;
  try {
    apply(r, gnssSection, file, c);
  } catch (const YAML::Exception& e) {
    throw ParseError(file, e.mark.line >= 0 ? e.mark.line + 1 : 0, "gnss", e.msg);
  }
  return c;
}

GnssSimConfig parseGnssSimConfigText(const std::string& yaml, const std::string& file) {
  YAML::Node root = YamlReader::loadText(yaml, file);
  if (root.IsNull()) return GnssSimConfig{};
  if (!root.IsMap()) {
    const auto m = root.Mark();
    throw ParseError(file, m.line >= 0 ? m.line + 1 : 0, "", "the scenario must be a map with a 'gnss' section");
  }
  YAML::Node g;
  try {
    g = root["gnss"];
  } catch (const YAML::Exception& e) {
    throw ParseError(file, e.mark.line >= 0 ? e.mark.line + 1 : 0, "gnss", e.msg);
  }
  return parseGnssSimConfig(g, file);
}

}  // namespace gvins::sim
