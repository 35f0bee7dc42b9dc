#include "gvins/ephemeris/precise_product_files.hpp"

#include <cctype>
#include <filesystem>

#include "gvins/ephemeris/rinex_clock.hpp"
#include "gvins/ephemeris/sp3.hpp"

namespace gvins {

PreciseFileKind preciseFileKind(std::string_view path) {
  std::string lower = std::filesystem::path(path).filename().string();
  for (char& ch : lower) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  if (lower.size() > 3 && lower.ends_with(".gz")) lower.resize(lower.size() - 3);
  if (lower.ends_with(".sp3")) return PreciseFileKind::kOrbit;
  if (lower.ends_with(".clk") || lower.ends_with(".clk_30s")) return PreciseFileKind::kClock;
  if (lower.ends_with(".atx")) return PreciseFileKind::kAntenna;
  if (lower.ends_with(".bia") || lower.ends_with(".bsx")) return PreciseFileKind::kBias;
  return PreciseFileKind::kOther;
}

std::shared_ptr<PreciseEphemeris> readPreciseProducts(const std::vector<std::string>& orbitFiles,
                                                      const std::vector<std::string>& clockFiles) {
  auto precise = std::make_shared<PreciseEphemeris>();
  for (const std::string& f : orbitFiles) precise->add(readSp3(f));
  for (const std::string& f : clockFiles) precise->add(readRinexClock(f));
  return precise;
}

std::shared_ptr<AntexData> readAntennaFiles(const std::vector<std::string>& files) {
  auto out = std::make_shared<AntexData>();
  for (const std::string& f : files) {
    AntexData d = readAntex(f);
    if (out->antennas.empty()) {  // the first file's header
      *out = std::move(d);
      continue;
    }
    for (AntexAntenna& a : d.antennas) out->antennas.push_back(std::move(a));
  }
  return out;
}

std::shared_ptr<BiasSinexData> readCodeBiasFiles(const std::vector<std::string>& files) {
  auto out = std::make_shared<BiasSinexData>();
  for (const std::string& f : files) {
    BiasSinexData d = readBiasSinex(f);
    if (out->entries.empty()) {
      *out = std::move(d);
      continue;
    }
    for (BiasEntry& e : d.entries) out->entries.push_back(std::move(e));
  }
  return out;
}

}  // namespace gvins
