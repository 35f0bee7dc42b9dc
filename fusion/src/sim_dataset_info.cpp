#include "gvins/fusion/sim_dataset_info.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "gvins/base/parse_error.hpp"
#include "gvins/base/yaml_reader.hpp"

namespace gvins::fusion {

SimDatasetInfo parseSimDatasetInfo(std::string_view yaml, const std::string& file) {
  YAML::Node root = YamlReader::loadText(std::string(yaml), file);
  const YamlReader r(file);
  SimDatasetInfo info;
  if (root.IsNull()) return info;
  if (!root.IsMap()) r.fail(root, "", "dataset.yaml must be a map");
  if (const YAML::Node l = root["lever_arm_m"]) {
    const auto v = r.numbers(l, "lever_arm_m", 3, -100.0, 100.0);
    info.leverArm = Eigen::Vector3d(v[0], v[1], v[2]);
  }
  if (const YAML::Node g = root["gravity"]) {
    if (!g.IsMap()) r.fail(g, "gravity", "'gravity' must be a map");
    if (const YAML::Node m = g["model"]) info.gravityModel = r.choice(m, "gravity.model", {"flat", "rotating"});
    if (const YAML::Node m = g["magnitude_mps2"]) info.gravity = r.number(m, "gravity.magnitude_mps2", 9.7, 9.9);
  }
  if (const YAML::Node c = root["cameras"]; c && c.IsMap()) {
    if (const YAML::Node t = c["time_offset_s"]) info.cameraTimeOffset = r.number(t, "cameras.time_offset_s", -0.5, 0.5);
  }
  return info;
}

std::optional<SimDatasetInfo> readSimDatasetInfo(const std::string& datasetFolder) {
  const std::filesystem::path p = std::filesystem::path(datasetFolder) / "dataset.yaml";
  if (!std::filesystem::exists(p)) return std::nullopt;
  return parseSimDatasetInfo(YamlReader::readFile(p.string()), p.string());
}

}  // namespace gvins::fusion
