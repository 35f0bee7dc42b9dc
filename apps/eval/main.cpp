// gvins-eval: accuracy of an estimated trajectory (TUM) against ground truth (EuRoC/ASL CSV or
// TUM): time association, alignment, absolute and relative errors, NEES, SVG plots.
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "gvins/base/command_line.hpp"
#include "gvins/base/line_reader.hpp"
#include "gvins/base/parse_error.hpp"
#include "gvins/vio/euroc_csv.hpp"
#include "gvins/vio/pose_covariance_csv.hpp"
#include "gvins/vio/trajectory_metrics.hpp"
#include "gvins/vio/tum_trajectory.hpp"

namespace fs = std::filesystem;
using namespace gvins::vio;

namespace {

const char* kUsage =
    "usage: gvins-eval [options] EST GT\n"
    "\n"
    "Accuracy of the estimated trajectory EST (TUM: 't x y z qx qy qz qw', t in seconds) against the\n"
    "ground truth GT: an EuRoC/ASL state_groundtruth_estimate0/data.csv (or a dataset folder that\n"
    "contains mav0/state_groundtruth_estimate0/data.csv), or a TUM file. Prints position, rotation\n"
    "and velocity errors (RMSE, mean, median, max), relative errors over travelled distance\n"
    "(drift %), and position/orientation NEES when pose covariances are available.\n"
    "\n"
    "  --align KIND       none | 4dof | se3 | sim3 | first (default se3). 4dof (yaw + translation) is\n"
    "                     the right choice for VIO, none for GNSS-fused global results, sim3 for\n"
    "                     mono; first: the 4-DoF transform of the first pose alone (the VIO's\n"
    "                     gauge: drift stays in the errors, the right one for NEES)\n"
    "  --gt-format F      auto | asl | tum (default auto: ASL if the first data line has a\n"
    "                     comma-separated integer nanosecond stamp)\n"
    "  --tolerance MS     time association tolerance, ms (default 20)\n"
    "  --segments L,...   relative-error segment lengths, m (default 10,50,100)\n"
    "  --align-first N    align on the first N matched poses only (default all)\n"
    "  --cov FILE         pose covariances (6x6 of [dtheta_body; dp_world] per pose, see\n"
    "                     docs/replay.md); default EST with its extension replaced by .cov.csv,\n"
    "                     used if it exists\n"
    "  --no-cov           ignore covariances\n"
    "  --whole            evaluate every pose of EST even when it has gvins-replay's VIO reset\n"
    "                     marks ('# VIO reset' comments; default: the poses after the last one,\n"
    "                     the others are in earlier VIO frames)\n"
    "  --plots PREFIX     write PREFIXtrajectory_top.svg, PREFIXposition_error.svg,\n"
    "                     PREFIXrotation_error.svg (PREFIX may be a folder ending in '/')\n"
    "  -h, --help         this text\n"
    "\n"
    "Exit status: 0 success, 1 input or evaluation error, 2 usage error.\n";

bool looksLikeAsl(const std::string& path) {
  gvins::LineReader r(path);
  std::string line;
  while (r.next(line)) {
    const auto b = line.find_first_not_of(" \t");
    if (b == std::string::npos || line[b] == '#') continue;
    const auto comma = line.find(',');
    if (comma == std::string::npos) return false;
    // Integer nanoseconds (optionally with a ".000" fraction) have >= 12 digits before any '.';
    // TUM seconds since 1970 have 10.
    const std::string first = line.substr(b, comma - b);
    const std::string whole = first.substr(0, first.find('.'));
    return whole.size() >= 12 && whole.find_first_not_of("0123456789") == std::string::npos;
  }
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> pos;
  EvaluationOptions opt;
  std::string gtFormat = "auto", covPath, plots;
  bool noCov = false;
  bool whole = false;
  gvins::CommandLine cl("gvins-eval", kUsage, argc, argv);
  while (cl.next()) {
    if (cl.is("--align")) {
      const std::string v = cl.value();
      const auto k = parseAlignmentKind(v);
      if (!k) cl.error("unknown alignment '" + v + "'");
      opt.alignment = *k;
    } else if (cl.is("--gt-format")) {
      gtFormat = cl.choice({"auto", "asl", "tum"});
    } else if (cl.is("--tolerance")) {
      opt.tolerance_ns = static_cast<std::int64_t>(cl.number(0.0, 1e6, "ms") * 1e6);
    } else if (cl.is("--segments")) {
      opt.segmentLengths = cl.numberList(1e-3, 1e7, "m");
    } else if (cl.is("--align-first")) {
      opt.alignFirst = static_cast<std::size_t>(cl.number(2.0, 1e9));
    } else if (cl.is("--cov")) {
      covPath = cl.value();
    } else if (cl.is("--no-cov")) {
      noCov = true;
    } else if (cl.is("--whole")) {
      whole = true;
    } else if (cl.is("--plots")) {
      plots = cl.value();
    } else {
      pos.push_back(cl.operand());
    }
  }
  if (pos.size() != 2) cl.error("need EST and GT");
  try {
    const std::string estPath = pos[0];
    std::string gtPath = pos[1];
    if (fs::is_directory(gtPath)) {
      for (const char* sub : {"mav0/state_groundtruth_estimate0/data.csv", "state_groundtruth_estimate0/data.csv"}) {
        if (fs::exists(fs::path(gtPath) / sub)) {
          gtPath = (fs::path(gtPath) / sub).string();
          break;
        }
      }
      if (fs::is_directory(gtPath)) throw std::runtime_error("no state_groundtruth_estimate0/data.csv in " + gtPath);
    }
    // gvins-replay marks an estimator restart (visual lock-out) in the TUM file; the poses before
    // the last mark are in other VIO frames.
    std::vector<std::size_t> marks;
    auto est = toTrajectorySamples(readTumTrajectory(estPath, TumTimeUnit::Seconds, &marks));
    if (!marks.empty() && !whole) {
      const std::size_t from = std::min(marks.back(), est.size());
      std::printf("%s has %zu VIO reset mark(s): evaluating the %zu poses after the last one (--whole: all)\n",
                  estPath.c_str(), marks.size(), est.size() - from);
      est.erase(est.begin(), est.begin() + static_cast<std::ptrdiff_t>(from));
    }
    if (est.empty()) throw std::runtime_error(estPath + ": no poses to evaluate (empty trajectory file)");
    const bool asl = gtFormat == "asl" || (gtFormat == "auto" && looksLikeAsl(gtPath));
    const auto gt = asl ? toTrajectorySamples(readGroundTruthCsv(gtPath)) : toTrajectorySamples(readTumTrajectory(gtPath));
    if (gt.empty()) throw std::runtime_error(gtPath + ": no reference poses (empty ground-truth file)");
    std::vector<PoseCovariance> cov;
    if (!noCov) {
      if (covPath.empty()) {
        const std::string guess = (fs::path(estPath).parent_path() / fs::path(estPath).stem()).string() + ".cov.csv";
        if (fs::exists(guess)) covPath = guess;
      }
      if (!covPath.empty()) cov = readPoseCovarianceCsv(covPath);
    }
    std::printf("estimate  %s (%zu poses)\nreference %s (%zu poses, %s)\n", estPath.c_str(), est.size(), gtPath.c_str(),
                gt.size(), asl ? "ASL" : "TUM");
    if (!covPath.empty()) std::printf("covariance %s (%zu rows)\n", covPath.c_str(), cov.size());
    const EvaluationResult r = evaluateTrajectory(est, gt, cov, opt);
    printEvaluation(std::cout, r);
    if (!plots.empty()) {
      if (plots.back() == '/') fs::create_directories(plots);
      for (const auto& f : writeEvaluationPlots(r, plots)) std::printf("wrote %s\n", f.c_str());
    }
    return 0;
  } catch (const gvins::ParseError& e) {
    std::fprintf(stderr, "gvins-eval: %s\n", e.what());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gvins-eval: %s\n", e.what());
  }
  return 1;
}
