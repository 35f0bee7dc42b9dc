// An output file written under a temporary name in its destination folder and renamed over the
// destination only when complete (rename(2) is atomic within a file system): a run that fails or
// is interrupted leaves no file that looks valid, and an older file of that name stays intact.
// A destination that exists and is not a regular file (/dev/null, a FIFO, a terminal) is written
// directly: renaming over it would replace the device or pipe with a regular file.
#pragma once

#include <fstream>
#include <optional>
#include <ostream>
#include <string>

namespace gvins {

class AtomicOutputFile {
 public:
  /// Reserves `path`; nothing is created until stream() or the caller writes tempPath().
  explicit AtomicOutputFile(std::string path);
  /// Removes the temporary file unless commit() succeeded.
  ~AtomicOutputFile();
  AtomicOutputFile(const AtomicOutputFile&) = delete;
  AtomicOutputFile& operator=(const AtomicOutputFile&) = delete;

  const std::string& path() const { return path_; }
  /// "<path>.part-<pid>" (same folder, so the final rename does not cross file systems); path()
  /// itself for a destination that is a device, FIFO or socket.
  const std::string& tempPath() const { return temp_; }
  /// The temporary file opened for writing (binary); throws std::runtime_error naming path()
  /// if it cannot be created.
  std::ofstream& stream();
  /// Flushes and closes the stream (if opened) and renames the temporary file to path();
  /// throws std::runtime_error naming path() on a write or rename failure.
  void commit();

 private:
  std::string path_, temp_;
  std::ofstream out_;
  bool opened_ = false, committed_ = false;
  bool direct_ = false;  // the destination is not a regular file: written in place
};

/// A tool's main output: standard output for "-", else an AtomicOutputFile opened at once.
class OutputTarget {
 public:
  /// Throws std::runtime_error naming `path` if the file cannot be created.
  explicit OutputTarget(const std::string& path);
  std::ostream& stream();
  bool isFile() const { return file_.has_value(); }
  /// The run's end: with `success` the file is renamed into place (throws std::runtime_error
  /// naming it on a write or rename failure), else it is discarded and no file is left.
  void finish(bool success);

 private:
  std::optional<AtomicOutputFile> file_;
};

}  // namespace gvins
