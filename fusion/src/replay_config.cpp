#include "gvins/fusion/replay_config.hpp"

#include "gvins/base/yaml_reader.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "gvins/base/parse_error.hpp"
#include "gvins/base/text_fields.hpp"

namespace gvins::fusion {

namespace {

std::int64_t lineOf(const YAML::Node& n) {
  const YAML::Mark m = n.Mark();
  return m.is_null() ? 0 : m.line + 1;
}

std::string scalar(const YAML::Node& n, const std::string& file, const std::string& key) {
  if (!n.IsScalar()) throw ParseError(file, lineOf(n), key, "expected a single value");
  return n.Scalar();
}

double number(const YAML::Node& n, const std::string& file, const std::string& key) {
  const std::string s = scalar(n, file, key);
  const double v = parseDouble(s, TextLocation{file, lineOf(n)}, key);
  if (!std::isfinite(v)) throw ParseError(file, lineOf(n), key, "value is not finite");
  return v;
}

bool boolean(const YAML::Node& n, const std::string& file, const std::string& key) {
  const std::string s = scalar(n, file, key);
  if (s == "true" || s == "on" || s == "yes") return true;
  if (s == "false" || s == "off" || s == "no") return false;
  throw ParseError(file, lineOf(n), key, "expected true or false, found '" + s + "'");
}

}  // namespace

ReplayConfig parseReplayConfig(std::string_view text, const std::string& file, const std::string& base_dir) {
  ReplayConfig c;
  c.text = std::string(text);
  c.file = file;
  const YAML::Node root = YamlReader::loadText(c.text, file);
  if (root.IsNull()) return c;
  if (!root.IsMap()) throw ParseError(file, lineOf(root), "", "expected a YAML mapping at the top level");
  try {
    for (const auto& kv : root) {
      if (!kv.first.IsScalar()) throw ParseError(file, lineOf(kv.first), "", "keys must be names");
      const std::string key = kv.first.Scalar();
      const YAML::Node& v = kv.second;
      if (key == "replay") {
        if (v.IsNull()) continue;
        if (!v.IsMap()) throw ParseError(file, lineOf(v), "replay", "expected a mapping");
        ReplayOptions& o = c.options;
        for (const auto& r : v) {
          if (!r.first.IsScalar()) throw ParseError(file, lineOf(r.first), "replay", "keys must be names");
          const std::string k = r.first.Scalar();
          const std::string name = "replay." + k;
          const YAML::Node& x = r.second;
          if (k == "max_imu_gap_s") {
            o.maxImuGap_s = number(x, file, name);
            if (!(o.maxImuGap_s > 0.0)) throw ParseError(file, lineOf(x), name, "must be positive");
          } else if (k == "imu_gaps") {
            const std::string s = scalar(x, file, name);
            if (s == "error") o.imuGapPolicy = ImuGapPolicy::Error;
            else if (s == "warn") o.imuGapPolicy = ImuGapPolicy::Warn;
            else throw ParseError(file, lineOf(x), name, "expected error or warn, found '" + s + "'");
          } else if (k == "skip_bad_images") {
            o.skipBadImages = boolean(x, file, name);
          } else if (k == "skip_missing_images") {
            o.skipMissingImages = boolean(x, file, name);
          } else if (k == "start_s") {
            o.start_s = number(x, file, name);
            if (o.start_s < 0.0) throw ParseError(file, lineOf(x), name, "must not be negative");
          } else if (k == "duration_s") {
            o.duration_s = number(x, file, name);
            if (o.duration_s < 0.0) throw ParseError(file, lineOf(x), name, "must not be negative");
          } else if (k == "feature_tracks") {
            o.useFeatureTracks = boolean(x, file, name);
          } else if (k == "evaluate") {
            o.evaluate = boolean(x, file, name);
          } else if (k == "stereo") {
            o.frontend.useStereo = boolean(x, file, name);
          } else if (k == "max_track_length") {
            const double n = number(x, file, name);
            if (!(n >= 0.0 && n <= 1e6) || n != static_cast<double>(static_cast<int>(n))) {
              throw ParseError(file, lineOf(x), name, "expected a whole number of images >= 0 (0: unlimited)");
            }
            o.frontend.tracker.maxTrackLength = static_cast<int>(n);
          } else if (k == "max_track_travel_px") {
            o.frontend.tracker.maxTrackTravel = number(x, file, name);
            if (!(o.frontend.tracker.maxTrackTravel >= 0.0)) {
              throw ParseError(file, lineOf(x), name, "must not be negative (0: unlimited)");
            }
          } else if (k == "klt_window_px") {
            const double n = number(x, file, name);
            if (!(n >= 5.0 && n <= 61.0) || n != static_cast<double>(static_cast<int>(n)) || static_cast<int>(n) % 2 == 0) {
              throw ParseError(file, lineOf(x), name, "expected an odd whole number of pixels in [5, 61]");
            }
            o.frontend.tracker.klt.window = static_cast<int>(n);
          } else if (k == "align_templates") {
            o.frontend.tracker.alignTemplates = boolean(x, file, name);
          } else if (k == "template_translation_fallback") {
            o.frontend.tracker.patch.translationFallback = boolean(x, file, name);
          } else if (k == "template_max_track_travel_px") {
            o.frontend.tracker.templateMaxTrackTravel = number(x, file, name);
            if (!(o.frontend.tracker.templateMaxTrackTravel >= 0.0)) {
              throw ParseError(file, lineOf(x), name, "must not be negative (0: unlimited)");
            }
          } else {
            throw ParseError(file, lineOf(r.first), name, "unknown key");
          }
        }
      } else if (key == "estimator") {
        const std::string p = scalar(v, file, "estimator");
        if (p.empty()) throw ParseError(file, lineOf(v), "estimator", "empty path");
        const std::filesystem::path fp(p);
        c.estimatorConfig = fp.is_absolute() ? p : (std::filesystem::path(base_dir) / fp).string();
      } else if (key == "gnss_fusion") {
        c.hasGnssFusion = true;
      } else {
        throw ParseError(file, lineOf(kv.first), key, "unknown key (expected replay, estimator or gnss_fusion)");
      }
    }
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
