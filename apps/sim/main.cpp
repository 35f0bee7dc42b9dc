// gvins-sim: writes a simulated GNSS-visual-inertial dataset folder (docs/dataset_format.md).
//
//   gvins-sim [--config SCENARIO.yaml] [--seed N] [--features-only] [--no-gnss] [--threads N] [--force] -o DIR
//
// Without --config it simulates the built-in default scenario (config/default.yaml): a
// two-minute stereo UAV survey near Nagoya on 2024-06-24 08:20 GPST with a base station 3 km
// away. Progress goes to stderr, a summary table to stdout at the end.
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <iostream>
#include <limits>
#include <optional>
#include <system_error>
#include <unistd.h>
#include <string>

#include "gvins/base/command_line.hpp"
#include "gvins/base/parse_error.hpp"
#include "gvins/sim/dataset_generator.hpp"
#include "gvins/sim/scenario.hpp"

namespace {

const char* kUsage =
    "usage: gvins-sim [--config SCENARIO.yaml] [--seed N] [--features-only] [--no-gnss] [--threads N] [--force] -o DIR\n"
    "  --config FILE     scenario (default: the built-in two-minute stereo UAV flight, config/default.yaml)\n"
    "  --seed N          random seed (default: the scenario's `seed`); same seed -> identical dataset\n"
    "  --features-only   write noisy feature tracks of 3-D landmarks instead of rendering images\n"
    "  --no-gnss         skip the GNSS part (rover/base observations, RTCM, navigation)\n"
    "  --threads N       rendering threads (default: all cores)\n"
    "  -o, --output DIR  dataset folder to write (created; written under a temporary name and renamed at\n"
    "                    the end, so a failed run leaves no dataset behind)\n"
    "  --force           replace DIR if it exists and is not empty (otherwise an error: files of an older\n"
    "                    dataset would mix with the new one)\n";

namespace fs = std::filesystem;

/// Generates into a sibling folder and renames it to `out` at the end; an existing non-empty
/// `out` is replaced only with `force`.
int generateInto(const gvins::sim::Scenario& sc, const fs::path& out, bool force,
                 const gvins::sim::GenerationOptions& opt) {
  std::error_code ec;
  const bool exists = fs::exists(out, ec);
  if (exists && !fs::is_directory(out, ec)) {
    std::cerr << "gvins-sim: -o " << out.string() << ": exists and is not a folder\n";
    return 1;
  }
  if (exists && !fs::is_empty(out, ec) && !force) {
    std::cerr << "gvins-sim: -o " << out.string()
              << ": folder exists and is not empty (its files would mix with the new dataset); "
                 "remove it or pass --force to replace it\n";
    return 1;
  }
  fs::path parent = out.parent_path();
  if (parent.empty()) parent = ".";
  fs::create_directories(parent);
  const fs::path temp = parent / (out.filename().string() + ".part-" + std::to_string(::getpid()));
  fs::remove_all(temp);
  struct Cleanup {
    fs::path p;
    bool keep = false;
    ~Cleanup() {
      std::error_code e;
      if (!keep) fs::remove_all(p, e);
    }
  } cleanup{temp};
  const gvins::sim::GenerationSummary sum = gvins::sim::generateDataset(sc, temp, opt);
  if (exists) fs::remove_all(out);
  fs::rename(temp, out);
  cleanup.keep = true;
  sum.print(std::cout);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::string config, out;
  std::optional<std::uint64_t> seed;
  bool force = false;
  gvins::sim::GenerationOptions opt;
  gvins::CommandLine cl("gvins-sim", kUsage, argc, argv);
  while (cl.next()) {
    if (cl.is("--config", "-c")) config = cl.value();
    else if (cl.is("--seed")) seed = cl.unsignedInteger(0, std::numeric_limits<std::uint64_t>::max());
    else if (cl.is("--features-only")) opt.featuresOnly = true;
    else if (cl.is("--no-gnss")) opt.gnss = false;
    else if (cl.is("--threads")) opt.threads = static_cast<int>(cl.integer(1, 64));
    else if (cl.is("-o", "--output")) out = cl.value();
    else if (cl.is("--force")) force = true;
    else cl.error("unknown argument '" + cl.arg() + "'");
  }
  if (out.empty()) cl.error("no output folder (-o DIR)");
  try {
    const gvins::sim::Scenario sc = config.empty() ? gvins::sim::defaultScenario() : gvins::sim::loadScenario(config);
    opt.seed = seed ? *seed : sc.seed;
    opt.progress = &std::cerr;
    return generateInto(sc, out, force, opt);
  } catch (const gvins::ParseError& e) {
    std::cerr << "gvins-sim: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "gvins-sim: error: " << e.what() << "\n";
    return 1;
  }
}
