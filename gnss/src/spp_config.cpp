#include "gvins/gnss/spp_config.hpp"

#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "gvins/base/parse_error.hpp"
#include "gvins/base/yaml_reader.hpp"

namespace gvins {

std::string bandListError(System s, std::string_view bands) {
  if (bands.empty()) return "empty band list";
  for (char ch : bands) {
    if (!isKnownBand(s, ch) && !(s == System::Glonass && (ch == '1' || ch == '2'))) {
      return std::string("band '") + ch + "' does not exist for " + std::string(systemName(s));
    }
  }
  return {};
}

namespace {

using Reader = YamlReader;

void applyReportedError(const Reader& r, const YAML::Node& v, const std::string& full, ReportedErrorModel& m) {
  static const std::set<std::string> kE = {"enabled", "noise_scale", "ionosphere_correlation_km", "min_variance_factor",
                                          "excess_correlation"};
  r.map(v, full, kE, [&](const std::string& ek, const std::string& ef, const YAML::Node& ev) {
    if (ek == "enabled") m.enabled = r.boolean(ev, ef);
    else if (ek == "noise_scale") m.noiseScale = r.number(ev, ef, 0.0, 100.0);
    else if (ek == "min_variance_factor") m.minVarianceFactor = r.number(ev, ef, 0.0, 1.0);
    else if (ek == "excess_correlation") m.excessCorrelation = r.number(ev, ef, 0.0, 1.0);
    else m.ionosphereCorrelationLength = r.number(ev, ef, 1.0, 1e5) * 1e3;
  });
}

void apply(const Reader& r, const YAML::Node& spp, SppConfig& c) {
  static const std::set<std::string> kKeys = {
      "systems", "elevation_mask_deg", "snr_mask_dbhz", "frequencies", "bands", "ionosphere", "troposphere",
      "relative_humidity", "meteo", "weighting", "ionosphere_model_error", "troposphere_zenith_error_m",
      "ephemeris_error_m", "ephemeris_alarm_accuracy_m", "precise_ephemeris_error_m", "fault_exclusion", "robust", "ionosphere_estimation", "covariance_scaling", "reported_error", "max_gdop", "isb_prior_sigma_m", "isb_random_walk_m2ps", "qzss_gps_clock",
      "max_iterations", "velocity", "carrier_smoothing_s", "allow_unhealthy"};
  r.map(spp, "spp", kKeys, [&](const std::string& k, const std::string& full, const YAML::Node& v) {
    if (k == "systems") {
      c.systems = r.systems(v, full);
    } else if (k == "elevation_mask_deg") {
      c.elevationMask = r.number(v, full, -10.0, 90.0) * constants::kDegToRad;
    } else if (k == "snr_mask_dbhz") {
      c.snrMask = r.number(v, full, 0.0, 100.0);
    } else if (k == "frequencies") {
      c.frequencies = r.integer(v, full, 1, 3);
    } else if (k == "bands") {
      r.perSystem(v, full, [&](System s, const std::string& f2, const YAML::Node& b) {
        const std::string bands = r.text(b, f2);
        if (const std::string e = bandListError(s, bands); !e.empty()) r.fail(b, f2, e);
        c.bands[systemIndex(s)] = bands;
      });
    } else if (k == "ionosphere") {
      c.ionosphere = r.choice(v, full, kIonosphereOptionNames);
    } else if (k == "troposphere") {
      c.troposphere = r.choice(v, full, kTroposphereOptionNames);
    } else if (k == "meteo") {
      const std::string t = r.text(v, full);
      if (t == "climatology") c.climatologicalMeteo = true;
      else if (t == "standard") c.climatologicalMeteo = false;
      else r.fail(v, full, "'" + full + "' must be climatology or standard, not '" + t + "'");
    } else if (k == "relative_humidity") {
      c.relativeHumidity = r.number(v, full, 0.0, 1.0);
    } else if (k == "weighting") {
      static const std::set<std::string> kW = {"scheme", "a_m", "b_m", "snr_reference_dbhz", "doppler_sigma_mps",
                                               "system_factor"};
      r.map(v, full, kW, [&](const std::string& wk, const std::string& wf, const YAML::Node& wv) {
        if (wk == "scheme") {
          const std::string t = r.text(wv, wf);
          if (t == "elevation") c.weighting.scheme = WeightingScheme::Elevation;
          else if (t == "snr") c.weighting.scheme = WeightingScheme::Snr;
          else if (t == "elevation-snr") c.weighting.scheme = WeightingScheme::ElevationSnr;
          else r.fail(wv, wf, "'" + wf + "' must be elevation, snr or elevation-snr, not '" + t + "'");
        } else if (wk == "a_m") {
          c.weighting.a = r.number(wv, wf, 0.0, 1000.0);
        } else if (wk == "b_m") {
          c.weighting.b = r.number(wv, wf, 0.0, 1000.0);
        } else if (wk == "snr_reference_dbhz") {
          c.weighting.snrReference = r.number(wv, wf, 0.0, 100.0);
        } else if (wk == "doppler_sigma_mps") {
          c.weighting.dopplerSigma = r.number(wv, wf, 1e-6, 1000.0);
        } else {
          r.perSystem(wv, wf, [&](System s, const std::string& f2, const YAML::Node& b) {
            c.weighting.systemFactor[systemIndex(s)] = r.number(b, f2, 0.01, 1000.0);
          });
        }
      });
      if (c.weighting.a <= 0.0 && c.weighting.b <= 0.0) r.fail(v, full, "weighting a_m and b_m cannot both be 0");
    } else if (k == "ionosphere_model_error") {
      c.ionosphereModelError = r.number(v, full, 0.0, 10.0);
    } else if (k == "troposphere_zenith_error_m") {
      c.troposphereZenithError = r.number(v, full, 0.0, 10.0);
    } else if (k == "ephemeris_error_m") {
      r.perSystem(v, full, [&](System s, const std::string& f2, const YAML::Node& b) {
        c.ephemerisError[systemIndex(s)] = r.number(b, f2, 0.0, 1000.0);
      });
    } else if (k == "precise_ephemeris_error_m") {
      r.perSystem(v, full, [&](System s, const std::string& f2, const YAML::Node& b) {
        c.preciseEphemerisError[systemIndex(s)] = r.number(b, f2, 0.0, 1000.0);
      });
    } else if (k == "ephemeris_alarm_accuracy_m") {
      c.ephemerisAlarmAccuracy = r.number(v, full, 0.0, 1e6);
    } else if (k == "fault_exclusion") {
      static const std::set<std::string> kF = {"enabled", "false_alarm_probability", "max_exclusions",
                                               "max_candidates", "min_redundancy"};
      r.map(v, full, kF, [&](const std::string& fk, const std::string& ff, const YAML::Node& fv) {
        if (fk == "enabled") c.faultExclusion.enabled = r.boolean(fv, ff);
        else if (fk == "false_alarm_probability") c.faultExclusion.falseAlarmProbability = r.number(fv, ff, 1e-12, 0.5);
        else if (fk == "max_exclusions") c.faultExclusion.maxExclusions = r.integer(fv, ff, 0, 100);
        else if (fk == "max_candidates") c.faultExclusion.maxCandidates = r.integer(fv, ff, 0, 1000);
        else c.faultExclusion.minRedundancy = r.integer(fv, ff, 0, 100);
      });
    } else if (k == "robust") {
      static const std::set<std::string> kR = {"enabled", "k0", "k1", "k0_failed", "k1_failed", "min_scale",
                                               "max_iterations"};
      r.map(v, full, kR, [&](const std::string& rk, const std::string& rf, const YAML::Node& rv) {
        if (rk == "enabled") c.robust.enabled = r.boolean(rv, rf);
        else if (rk == "k0") c.robust.k0 = r.number(rv, rf, 0.1, 100.0);
        else if (rk == "k1") c.robust.k1 = r.number(rv, rf, 0.2, 1000.0);
        else if (rk == "k0_failed") c.robust.k0Failed = r.number(rv, rf, 0.1, 100.0);
        else if (rk == "k1_failed") c.robust.k1Failed = r.number(rv, rf, 0.2, 1000.0);
        else if (rk == "min_scale") c.robust.minScale = r.number(rv, rf, 0.0, 100.0);
        else c.robust.maxIterations = r.integer(rv, rf, 1, 100);
      });
      if (c.robust.k1 <= c.robust.k0) r.fail(v, full, "robust.k1 must be larger than robust.k0");
      if (c.robust.k1Failed <= c.robust.k0Failed) r.fail(v, full, "robust.k1_failed must be larger than robust.k0_failed");
    } else if (k == "ionosphere_estimation") {
      static const std::set<std::string> kI = {"enabled", "prior_fraction", "min_prior_sigma_m"};
      r.map(v, full, kI, [&](const std::string& ik, const std::string& iff, const YAML::Node& iv) {
        if (ik == "enabled") c.ionosphereEstimation.enabled = r.boolean(iv, iff);
        else if (ik == "prior_fraction") c.ionosphereEstimation.priorFraction = r.number(iv, iff, 0.0, 10.0);
        else c.ionosphereEstimation.minPriorSigma = r.number(iv, iff, 0.001, 100.0);
      });
    } else if (k == "covariance_scaling") {
      static const std::set<std::string> kC = {"enabled", "prior_dof"};
      r.map(v, full, kC, [&](const std::string& ck, const std::string& cf, const YAML::Node& cv) {
        if (ck == "enabled") c.covarianceScaling.enabled = r.boolean(cv, cf);
        else c.covarianceScaling.priorDof = r.number(cv, cf, 0.0, 1000.0);
      });
    } else if (k == "reported_error") {
      applyReportedError(r, v, full, c.reportedError);
    } else if (k == "max_gdop") {
      c.maxGdop = r.number(v, full, 1.0, 1e6);
    } else if (k == "isb_prior_sigma_m") {
      c.isbPriorSigma = r.number(v, full, 0.0, 1e6);
    } else if (k == "isb_random_walk_m2ps") {
      c.isbRandomWalk = r.number(v, full, 0.0, 1e6);
    } else if (k == "qzss_gps_clock") {
      c.qzssUsesGpsClock = r.boolean(v, full);
    } else if (k == "max_iterations") {
      c.maxIterations = r.integer(v, full, 1, 100);
    } else if (k == "velocity") {
      c.velocity = r.boolean(v, full);
    } else if (k == "carrier_smoothing_s") {
      c.carrierSmoothing = r.number(v, full, 0.0, 3600.0);
    } else if (k == "allow_unhealthy") {
      c.ephemeris.allowUnhealthy = r.boolean(v, full);
    }
  });
}

}  // namespace

SppConfig parseSppConfig(std::string_view yaml, std::string_view name, const SppConfig& base) {
  SppConfig c = base;
  const Reader r{std::string(name)};
  const YAML::Node root = YamlReader::loadText(std::string(yaml), std::string(name));
  if (root.IsNull()) return c;  // empty file: defaults
  if (!root.IsMap()) r.fail(root, "", "the configuration must be a map with an 'spp' section");
  try {
    // spp: and rtk: share files (gvins-rtk reads both); anything else is a mistake.
    r.sections(root, {"spp", "rtk"});
    const YAML::Node spp = root["spp"];
    if (!spp || spp.IsNull()) return c;
    apply(r, spp, c);
  } catch (const YAML::Exception& e) {
    // Anything yaml-cpp itself rejects while walking the document (odd keys, aliases...).
    throw ParseError(std::string(name), e.mark.line >= 0 ? e.mark.line + 1 : 0, "YAML", e.msg);
  }
  return c;
}

SppConfig loadSppConfig(const std::string& path, const SppConfig& base) {
  return parseSppConfig(YamlReader::readFile(path), path, base);
}

}  // namespace gvins
