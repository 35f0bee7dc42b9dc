#include "gvins/fusion/replay_config.hpp"

#include <filesystem>
#include <limits>
#include <set>

#include <yaml-cpp/yaml.h>

#include "gvins/base/parse_error.hpp"
#include "gvins/base/yaml_reader.hpp"

namespace gvins::fusion {

namespace {

/// A whole number in [lo, hi] written as an integer or a float without fraction ("30", "30.0").
int wholeNumber(const YamlReader& r, const YAML::Node& v, const std::string& key, double lo, double hi, const char* what) {
  const double n = r.number(v, key, -std::numeric_limits<double>::max(), std::numeric_limits<double>::max());
  if (!(n >= lo && n <= hi) || n != static_cast<double>(static_cast<int>(n))) r.fail(v, key, what);
  return static_cast<int>(n);
}

/// A number >= 0 (`what` explains the limit).
double nonNegative(const YamlReader& r, const YAML::Node& v, const std::string& key, const char* what) {
  const double x = r.number(v, key, -std::numeric_limits<double>::max(), std::numeric_limits<double>::max());
  if (x < 0.0) r.fail(v, key, what);
  return x;
}

void parseReplaySection(const YamlReader& r, const YAML::Node& section, ReplayOptions& o) {
  static const std::set<std::string> kKeys = {
      "max_imu_gap_s", "imu_gaps", "skip_bad_images", "skip_missing_images", "start_s", "duration_s",
      "feature_tracks", "evaluate", "stereo", "max_track_length", "max_track_travel_px", "klt_window_px",
      "align_templates", "template_translation_fallback", "template_max_track_travel_px"};
  constexpr double kMax = std::numeric_limits<double>::max();
  r.map(section, "replay", kKeys, [&](const std::string& k, const std::string& name, const YAML::Node& x) {
    if (k == "max_imu_gap_s") {
      o.maxImuGap_s = r.number(x, name, -kMax, kMax);
      if (!(o.maxImuGap_s > 0.0)) r.fail(x, name, "must be positive");
    } else if (k == "imu_gaps") {
      o.imuGapPolicy = r.choice(x, name, kImuGapPolicyNames);
    } else if (k == "skip_bad_images") {
      o.skipBadImages = r.boolean(x, name);
    } else if (k == "skip_missing_images") {
      o.skipMissingImages = r.boolean(x, name);
    } else if (k == "start_s") {
      o.start_s = nonNegative(r, x, name, "must not be negative");
    } else if (k == "duration_s") {
      o.duration_s = nonNegative(r, x, name, "must not be negative");
    } else if (k == "feature_tracks") {
      o.useFeatureTracks = r.boolean(x, name);
    } else if (k == "evaluate") {
      o.evaluate = r.boolean(x, name);
    } else if (k == "stereo") {
      o.frontend.useStereo = r.boolean(x, name);
    } else if (k == "max_track_length") {
      o.frontend.tracker.maxTrackLength =
          wholeNumber(r, x, name, 0.0, 1e6, "expected a whole number of images >= 0 (0: unlimited)");
    } else if (k == "max_track_travel_px") {
      o.frontend.tracker.maxTrackTravel = nonNegative(r, x, name, "must not be negative (0: unlimited)");
    } else if (k == "klt_window_px") {
      const int n = wholeNumber(r, x, name, 5.0, 61.0, "expected an odd whole number of pixels in [5, 61]");
      if (n % 2 == 0) r.fail(x, name, "expected an odd whole number of pixels in [5, 61]");
      o.frontend.tracker.klt.window = n;
    } else if (k == "align_templates") {
      o.frontend.tracker.alignTemplates = r.boolean(x, name);
    } else if (k == "template_translation_fallback") {
      o.frontend.tracker.patch.translationFallback = r.boolean(x, name);
    } else if (k == "template_max_track_travel_px") {
      o.frontend.tracker.templateMaxTrackTravel = nonNegative(r, x, name, "must not be negative (0: unlimited)");
    }
  });
}

}  // namespace

ReplayConfig parseReplayConfig(std::string_view text, const std::string& file, const std::string& base_dir) {
  ReplayConfig c;
  c.text = std::string(text);
  c.file = file;
  const YamlReader r(file);
  const YAML::Node root = YamlReader::loadText(c.text, file);
  if (root.IsNull()) return c;
  if (!root.IsMap()) r.fail(root, "", "expected a YAML mapping at the top level");
  try {
    r.map(root, "", {"replay", "estimator", "gnss_fusion"}, [&](const std::string& key, const std::string&, const YAML::Node& v) {
      if (key == "replay") {
        if (!v.IsNull()) parseReplaySection(r, v, c.options);
      } else if (key == "estimator") {
        const std::string p = r.text(v, "estimator");
        if (p.empty()) r.fail(v, "estimator", "empty path");
        const std::filesystem::path fp(p);
        c.estimatorConfig = fp.is_absolute() ? p : (std::filesystem::path(base_dir) / fp).string();
      } else {
        c.hasGnssFusion = true;
      }
    });
  } catch (const YAML::Exception& e) {
    throw ParseError(file, e.mark.is_null() ? 0 : e.mark.line + 1, "YAML", e.msg);
  }
  return c;
}

ReplayConfig loadReplayConfig(const std::string& path) {
  const std::string text = YamlReader::readFile(path);
  const std::filesystem::path p(path);
  return parseReplayConfig(text, path, p.has_parent_path() ? p.parent_path().string() : ".");
}

}  // namespace gvins::fusion
