#include "gvins/base/atomic_output_file.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <stdexcept>

namespace gvins {

AtomicOutputFile::AtomicOutputFile(std::string path)
    : path_(std::move(path)), temp_(path_ + ".part-" + std::to_string(::getpid())) {
  struct stat st {};
  if (::stat(path_.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode)) {
    temp_ = path_;
    direct_ = true;
  }
}

AtomicOutputFile::~AtomicOutputFile() {
  if (committed_ || direct_) return;
  if (out_.is_open()) out_.close();
  std::remove(temp_.c_str());
}

std::ofstream& AtomicOutputFile::stream() {
  if (!opened_) {
    out_.open(temp_, std::ios::binary | std::ios::trunc);
    if (!out_) throw std::runtime_error("cannot create '" + path_ + "': " + std::strerror(errno));
    opened_ = true;
  }
  return out_;
}

void AtomicOutputFile::commit() {
  if (committed_) return;
  if (opened_) {
    out_.flush();
    const bool good = static_cast<bool>(out_);
    out_.close();
    if (!good || out_.fail()) throw std::runtime_error("cannot write '" + path_ + "' (disk full?)");
  }
  if (!direct_ && std::rename(temp_.c_str(), path_.c_str()) != 0)
    throw std::runtime_error("cannot write '" + path_ + "': " + std::strerror(errno));
  committed_ = true;
}

OutputTarget::OutputTarget(const std::string& path) {
  if (path == "-") return;
  file_.emplace(path);
  file_->stream();
}

std::ostream& OutputTarget::stream() { return file_ ? static_cast<std::ostream&>(file_->stream()) : std::cout; }

void OutputTarget::finish(bool success) {
  if (!file_) {
    std::cout.flush();
    return;
  }
  if (success) file_->commit();
  else file_.reset();
}

}  // namespace gvins
