// AtomicOutputFile: the destination appears only on commit(); a failure (no commit) leaves
// neither a partial file nor a temporary one, and an older file stays intact.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <sys/stat.h>

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

TEST(AtomicOutputFile, DevicesAndPipesAreWrittenInPlaceNotReplaced) {
  // `-o /dev/null` or a named pipe: a rename over it would turn the device or pipe into a regular
  // file (as root, /dev/null itself). A FIFO stands for both here.
  const fs::path dir = fs::temp_directory_path() / ("gvins_atomic_fifo_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path fifo = dir / "pipe";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::string got;
  std::thread reader([&] { got = slurp(fifo); });
  {
    OutputTarget t(fifo.string());
    t.stream() << "row 1\nrow 2\n";
    t.finish(true);
  }
  if (!fs::is_fifo(fifo)) {  // replaced: the reader waits on the old pipe for ever
    reader.detach();
    FAIL() << "the pipe was replaced by a regular file";
  }
  reader.join();
  EXPECT_EQ(got, "row 1\nrow 2\n");
  EXPECT_FALSE(fs::exists(fifo.string() + ".part-" + std::to_string(::getpid())));
  // A character device is kept as well (writing to /dev/null is harmless).
  {
    AtomicOutputFile f("/dev/null");
    EXPECT_EQ(f.tempPath(), "/dev/null");
    f.stream() << "discarded";
    f.commit();
  }
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
  fs::remove_all(dir);
}
