// A temporary folder for everything one test process writes, removed when the process ends:
// temp_directory_path()/<prefix><pid>. The first call creates the path (not the folder) and fixes
// the prefix; later calls return the same path.
#pragma once

#include <filesystem>
#include <string>
#include <system_error>
#include <unistd.h>

namespace gvins::fusion::test {

inline const std::filesystem::path& processScratchFolder(const std::string& prefix) {
  struct Folder {
    std::filesystem::path path;
    ~Folder() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static const Folder f{std::filesystem::temp_directory_path() / (prefix + std::to_string(::getpid()))};
  return f.path;
}

}  // namespace gvins::fusion::test
