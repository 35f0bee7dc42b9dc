// AtomicOutputFile: the destination appears only on commit(); a failure (no commit) leaves
// neither a partial file nor a temporary one, and an older file stays intact.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "gvins/base/atomic_output_file.hpp"

using namespace gvins;
namespace fs = std::filesystem;

namespace {
std::string slurp(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}
}  // namespace

TEST(AtomicOutputFile, AppearsOnlyWhenCommitted) {
  const fs::path dir = fs::temp_directory_path() / ("gvins_atomic_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path out = dir / "result.txt";
  std::ofstream(out) << "old\n";
  try {
    AtomicOutputFile f(out.string());
    f.stream() << "half of a new file";
    EXPECT_EQ(slurp(out), "old\n");  // not visible while being written
    throw std::runtime_error("the run fails here");
  } catch (const std::runtime_error&) {
  }
  EXPECT_EQ(slurp(out), "old\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);  // no temporary left
  {
    AtomicOutputFile f(out.string());
    f.stream() << "new\n";
    f.commit();
  }
  EXPECT_EQ(slurp(out), "new\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
  // A destination in a folder that does not exist cannot be created: an error naming it.
  AtomicOutputFile bad((dir / "missing" / "x.txt").string());
  try {
    bad.stream();
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("missing/x.txt"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}
