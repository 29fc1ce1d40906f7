// Outputs of the example programs that appear only when complete. OutputFile writes under a
// temporary name in the same folder (FILE.tmp) and renames it into place once every byte has
// reached the file system; a run that fails half-way (a bad value met on the way, a diverged
// simulation, a full disk) leaves no file that looks complete, and a write error is an error that
// names the file. Devices and pipes (/dev/stdout, /dev/full, a FIFO) are written in place, as
// they cannot be renamed onto. OutputFolder removes the folders the program created (the output
// folder and any new parents) if the program fails before keep().
#pragma once

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <utility>

#include "manisoft/core/error.hpp"

namespace manisoft::cli {

class OutputFile {
 public:
  explicit OutputFile(std::string path) : path_(std::move(path)) {
    std::error_code ec;
    const auto status = std::filesystem::status(path_, ec);
    const bool in_place = !ec && std::filesystem::exists(status) && !std::filesystem::is_regular_file(status);
    written_ = in_place ? path_ : path_ + ".tmp";
    out_.open(written_, std::ios::binary | std::ios::trunc);
    if (!out_) manisoft::detail::fail("cannot write '", path_, "': ", std::strerror(errno));
    temporary_ = !in_place;
  }
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;
  ~OutputFile() {
    if (committed_) return;
    out_.close();
    if (temporary_) std::remove(written_.c_str());
  }

  std::ofstream& stream() { return out_; }
  const std::string& path() const { return path_; }

  /// Closes the file, checks that everything was written and moves it into place; throws
  /// manisoft::Error naming the file otherwise (and removes the temporary file).
  void commit() {
    out_.flush();
    const int flush_errno = out_ ? 0 : errno;
    out_.close();
    if (out_.fail()) {
      if (temporary_) std::remove(written_.c_str());
      manisoft::detail::fail("writing '", path_, "' failed: ", std::strerror(flush_errno ? flush_errno : errno));
    }
    if (temporary_ && std::rename(written_.c_str(), path_.c_str()) != 0) {
      const int e = errno;
      std::remove(written_.c_str());
      manisoft::detail::fail("cannot move '", written_, "' to '", path_, "': ", std::strerror(e));
    }
    committed_ = true;
  }

 private:
  std::string path_, written_;
  std::ofstream out_;
  bool temporary_ = false, committed_ = false;
};

class OutputFolder {
 public:
  /// Creates `path` (and its parents) if missing; throws manisoft::Error naming it on failure.
  explicit OutputFolder(std::filesystem::path path) : path_(std::move(path)) {
    std::error_code ec;
    for (auto p = path_; !p.empty() && !std::filesystem::exists(p, ec); p = p.parent_path()) {
      created_ = p;  // the outermost folder that is new
      if (p == p.parent_path()) break;
    }
    std::filesystem::create_directories(path_, ec);
    if (ec) manisoft::detail::fail("cannot create the folder '", path_.string(), "': ", ec.message());
  }
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;
  ~OutputFolder() {
    std::error_code ignored;
    if (!created_.empty() && !kept_) std::filesystem::remove_all(created_, ignored);
  }
  const std::filesystem::path& path() const { return path_; }
  void keep() { kept_ = true; }

 private:
  std::filesystem::path path_, created_;  // created_: empty when the folder was there before
  bool kept_ = false;
};

}  // namespace manisoft::cli
