#include "gvins/gnss/rtk_config.hpp"

#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "gvins/base/parse_error.hpp"
#include "gvins/base/yaml_reader.hpp"
#include "gvins/gnss/spp_config.hpp"

namespace gvins {

const char* toString(RtkMode m) { return enumName(kRtkModeNames, m); }
const char* toString(AmbiguityMode m) { return enumName(kAmbiguityModeNames, m); }
const char* toString(RtkDynamics d) { return enumName(kRtkDynamicsNames, d); }
const char* toString(SignalMatching m) { return enumName(kSignalMatchingNames, m); }

namespace {

using Reader = YamlReader;  // base/yaml_reader.hpp

void applyAr(const Reader& r, const YAML::Node& v, const std::string& where, RtkConfig& c) {
  static const std::set<std::string> kKeys = {
      "systems", "elevation_mask_deg", "min_lock", "validation", "ratio_threshold", "max_failure_rate", "partial",
      "partial_success_rate", "min_fixed", "min_satellites", "max_partial_attempts", "max_search_nodes", "hold_min_fixes",
      "hold_sigma_cycles", "validation_sigmas", "ffrt_samples", "max_fixed_sigma_m", "position_test_alpha",
      "code_validation_sigmas", "confirm_ratio_factor"};
  r.map(v, where, kKeys, [&](const std::string& k, const std::string& f, const YAML::Node& x) {
    if (k == "systems") c.arSystems = r.systems(x, f);
    else if (k == "elevation_mask_deg") c.arElevationMask = r.number(x, f, 0.0, 90.0) * constants::kDegToRad;
    else if (k == "min_lock") c.arMinLock = r.integer(x, f, 0, 100000);
    else if (k == "validation") c.ar.validation = r.choice(x, f, kAmbiguityValidationNames);
    else if (k == "ratio_threshold") c.ar.ratioThreshold = r.number(x, f, 1.0, 1000.0);
    else if (k == "max_failure_rate") c.ar.maxFailureRate = r.number(x, f, 1e-9, 0.5);
    else if (k == "partial") c.ar.partial = r.boolean(x, f);
    else if (k == "partial_success_rate") c.ar.partialSuccessRate = r.number(x, f, 0.5, 1.0);
    else if (k == "min_fixed") c.ar.minFixed = r.integer(x, f, 1, 1000);
    else if (k == "min_satellites") c.arMinSatellites = r.integer(x, f, 2, 1000);
    else if (k == "max_partial_attempts") c.ar.maxPartialAttempts = r.integer(x, f, 0, 1000);
    else if (k == "max_search_nodes") c.ar.maxNodes = r.integer(x, f, 100, 100000000);
    else if (k == "hold_min_fixes") c.holdMinFixes = r.integer(x, f, 1, 100000);
    else if (k == "hold_sigma_cycles") c.holdSigmaCycles = r.number(x, f, 1e-6, 1.0);
    else if (k == "validation_sigmas") c.fixValidationSigmas = r.number(x, f, 1.0, 100.0);
    else if (k == "ffrt_samples") c.ar.ffrtSamples = r.integer(x, f, 100, 1000000);
    else if (k == "max_fixed_sigma_m") c.maxFixedSigma = r.number(x, f, 1e-4, 100.0);
    else if (k == "position_test_alpha") c.fixPositionTestAlpha = r.number(x, f, 0.0, 0.5);
    else if (k == "code_validation_sigmas") c.fixCodeValidationSigmas = r.number(x, f, 1.0, 1000.0);
    else c.confirmRatioFactor = r.number(x, f, 1.0, 1000.0);
  });
}

void apply(const Reader& r, const YAML::Node& rtk, RtkConfig& c) {
  static const std::set<std::string> kKeys = {
      "mode", "dynamics", "ambiguity_mode", "systems", "frequencies", "bands", "signal_matching", "elevation_mask_deg",
      "snr_mask_dbhz", "ar", "phase_sigma_m", "code_phase_ratio", "code_system_factor", "troposphere", "ionosphere", "base",
      "cycle_slip", "ambiguity_outage_s", "outliers", "filter"};
  r.map(rtk, "rtk", kKeys, [&](const std::string& k, const std::string& full, const YAML::Node& v) {
    if (k == "mode") {
      c.mode = r.choice(v, full, kRtkModeNames);
    } else if (k == "dynamics") {
      c.dynamics = r.choice(v, full, kRtkDynamicsNames);
    } else if (k == "ambiguity_mode") {
      c.ambiguityMode = r.choice(v, full, kAmbiguityModeNames);
    } else if (k == "systems") {
      c.systems = r.systems(v, full);
    } else if (k == "frequencies") {
      c.frequencies = r.integer(v, full, 1, 3);
    } else if (k == "bands") {
      r.perSystem(v, full, [&](System s, const std::string& f2, const YAML::Node& b) {
        const std::string bands = r.text(b, f2);
        if (bands.empty()) r.fail(b, f2, "empty band list");
        for (char ch : bands) {
          if (!isKnownBand(s, ch) && !(s == System::Glonass && (ch == '1' || ch == '2'))) {
            r.fail(b, f2, std::string("band '") + ch + "' does not exist for " + std::string(systemName(s)));
          }
          if (bands.find(ch) != bands.rfind(ch)) r.fail(b, f2, std::string("band '") + ch + "' listed twice");
        }
        c.bands[systemIndex(s)] = bands;
      });
    } else if (k == "signal_matching") {
      c.signalMatching = r.choice(v, full, kSignalMatchingNames);
    } else if (k == "elevation_mask_deg") {
      c.elevationMask = r.number(v, full, -10.0, 90.0) * constants::kDegToRad;
    } else if (k == "snr_mask_dbhz") {
      c.snrMask = r.number(v, full, 0.0, 100.0);
    } else if (k == "ar") {
      applyAr(r, v, full, c);
    } else if (k == "phase_sigma_m") {
      static const std::set<std::string> kP = {"a", "b"};
      r.map(v, full, kP, [&](const std::string& pk, const std::string& pf, const YAML::Node& pv) {
        if (pk == "a") c.phaseSigmaA = r.number(pv, pf, 0.0, 1.0);
        else c.phaseSigmaB = r.number(pv, pf, 0.0, 1.0);
      });
      if (c.phaseSigmaA <= 0.0 && c.phaseSigmaB <= 0.0) r.fail(v, full, "phase_sigma_m a and b cannot both be 0");
    } else if (k == "code_phase_ratio") {
      c.codePhaseRatio = r.number(v, full, 1.0, 100000.0);
    } else if (k == "code_system_factor") {
      r.perSystem(v, full, [&](System s, const std::string& f2, const YAML::Node& b) {
        c.codeSystemFactor[systemIndex(s)] = r.number(b, f2, 0.01, 1000.0);
      });
    } else if (k == "troposphere") {
      c.troposphere = r.boolean(v, full);
    } else if (k == "ionosphere") {
      static const std::set<std::string> kI = {"sigma_ppm", "rate_ppm", "min_sigma_m"};
      r.map(v, full, kI, [&](const std::string& ik, const std::string& iff, const YAML::Node& iv) {
        if (ik == "sigma_ppm") c.ionosphereSigmaPpm = r.number(iv, iff, 0.0, 1000.0);
        else if (ik == "rate_ppm") c.ionosphereRatePpm = r.number(iv, iff, 0.0, 1000.0);
        else c.ionosphereMinSigma = r.number(iv, iff, 0.0, 10.0);
      });
    } else if (k == "base") {
      static const std::set<std::string> kB = {"max_age_s", "interpolate", "max_interpolation_gap_s", "extrapolate"};
      r.map(v, full, kB, [&](const std::string& bk, const std::string& bf, const YAML::Node& bv) {
        if (bk == "max_age_s") c.maxAge = r.number(bv, bf, 0.0, 86400.0);
        else if (bk == "interpolate") c.interpolateBase = r.boolean(bv, bf);
        else if (bk == "extrapolate") c.extrapolateBase = r.boolean(bv, bf);
        else c.maxInterpolationGap = r.number(bv, bf, 0.0, 86400.0);
      });
    } else if (k == "cycle_slip") {
      static const std::set<std::string> kS = {"lli", "max_gap_s", "geometry_free", "geometry_free_m",
                                               "geometry_free_rate_mps", "doppler", "doppler_m", "doppler_jerk_mps3"};
      r.map(v, full, kS, [&](const std::string& sk, const std::string& sf, const YAML::Node& sv) {
        if (sk == "lli") c.slip.useLli = r.boolean(sv, sf);
        else if (sk == "max_gap_s") c.slip.maxGap = r.number(sv, sf, 0.0, 86400.0);
        else if (sk == "geometry_free") c.slip.geometryFree = r.boolean(sv, sf);
        else if (sk == "geometry_free_m") c.slip.geometryFreeThreshold = r.number(sv, sf, 1e-4, 100.0);
        else if (sk == "geometry_free_rate_mps") c.slip.geometryFreeRate = r.number(sv, sf, 0.0, 10.0);
        else if (sk == "doppler") c.slip.doppler = r.boolean(sv, sf);
        else if (sk == "doppler_m") c.slip.dopplerThreshold = r.number(sv, sf, 1e-3, 1e4);
        else c.slip.dopplerJerk = r.number(sv, sf, 0.0, 1e4);
      });
    } else if (k == "ambiguity_outage_s") {
      c.ambiguityOutage = r.number(v, full, 0.0, 86400.0);
    } else if (k == "outliers") {
      static const std::set<std::string> kO = {"code_gate_m", "phase_sigmas", "code_sigmas", "max_rounds"};
      r.map(v, full, kO, [&](const std::string& ok, const std::string& of, const YAML::Node& ov) {
        if (ok == "code_gate_m") c.codeInnovationGate = r.number(ov, of, 0.1, 1e6);
        else if (ok == "phase_sigmas") c.phaseOutlierSigmas = r.number(ov, of, 1.0, 1000.0);
        else if (ok == "code_sigmas") c.codeOutlierSigmas = r.number(ov, of, 1.0, 1000.0);
        else c.maxOutlierRounds = r.integer(ov, of, 0, 100);
      });
    } else if (k == "filter") {
      static const std::set<std::string> kF = {"initial_position_sigma_m", "ambiguity_sigma_m", "random_walk_mpsqrts",
                                               "doppler_aided", "doppler_aided_mpsqrts", "acceleration_h_mps2",
                                               "acceleration_v_mps2", "max_spp_deviation_m"};
      r.map(v, full, kF, [&](const std::string& fk, const std::string& ff, const YAML::Node& fv) {
        if (fk == "initial_position_sigma_m") c.initialPositionSigma = r.number(fv, ff, 0.01, 1e7);
        else if (fk == "ambiguity_sigma_m") c.ambiguityInitialSigma = r.number(fv, ff, 0.01, 1e6);
        else if (fk == "random_walk_mpsqrts") c.randomWalkSigma = r.number(fv, ff, 0.0, 1e6);
        else if (fk == "doppler_aided") c.dopplerAided = r.boolean(fv, ff);
        else if (fk == "doppler_aided_mpsqrts") c.dopplerAidedSigma = r.number(fv, ff, 0.0, 1e6);
        else if (fk == "acceleration_h_mps2") c.accelerationSigmaHorizontal = r.number(fv, ff, 0.0, 1e4);
        else if (fk == "acceleration_v_mps2") c.accelerationSigmaVertical = r.number(fv, ff, 0.0, 1e4);
        else c.maxSppDeviation = r.number(fv, ff, 1.0, 1e7);
      });
    }
  });
  // Cross-key consistency.
  bool any = false;
  for (bool b : c.systems) any = any || b;
  if (!any) r.fail(rtk, "rtk.systems", "no satellite system enabled");
}

}  // namespace

RtkConfig parseRtkConfig(std::string_view yaml, std::string_view name, const RtkConfig& base) {
  RtkConfig c = base;
  const Reader r{std::string(name)};
  YAML::Node root = YamlReader::loadText(std::string(yaml), std::string(name));
  if (root.IsNull()) return c;
  if (!root.IsMap()) r.fail(root, "", "the configuration must be a map with an 'rtk' section");
  try {
    // spp: and rtk: share files (gvins-rtk reads both); anything else is a mistake.
    r.sections(root, {"spp", "rtk"});
    const YAML::Node rtk = root["rtk"];
    if (!rtk || rtk.IsNull()) return c;
    apply(r, rtk, c);
  } catch (const YAML::Exception& e) {
    throw ParseError(std::string(name), e.mark.line >= 0 ? e.mark.line + 1 : 0, "YAML", e.msg);
  }
  return c;
}

RtkConfig loadRtkConfig(const std::string& path, const RtkConfig& base) {
  return parseRtkConfig(YamlReader::readFile(path), path, base);
}

}  // namespace gvins
