// A scratch folder for one test process: ctest runs test cases of the same program in parallel
// (one process each), so a folder shared by name would let one case read another's files. The
// folders are removed when the process exits (MANISOFT_KEEP_SCRATCH=1 keeps them, to look at the
// files of a failed test).
#pragma once

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

namespace manisoft::test {

namespace detail {

/// The process's scratch folders, removed by its destructor at exit.
struct ScratchFolders {
  std::vector<std::filesystem::path> folders;
  ScratchFolders() = default;
  ScratchFolders(const ScratchFolders&) = delete;
  ScratchFolders& operator=(const ScratchFolders&) = delete;
  ~ScratchFolders() {
    const char* keep = std::getenv("MANISOFT_KEEP_SCRATCH");
    if (keep && *keep && std::string(keep) != "0") return;
    std::error_code ignored;
    for (const auto& f : folders) std::filesystem::remove_all(f, ignored);
  }
};

inline ScratchFolders& scratch_folders() {
  static ScratchFolders folders;
  return folders;
}

}  // namespace detail

/// `<temp>/<name>_<pid>`, created if missing; removed when the process exits.
inline std::filesystem::path scratch_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / (name + "_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  auto& folders = detail::scratch_folders().folders;
  if (std::find(folders.begin(), folders.end(), dir) == folders.end()) folders.push_back(dir);
  return dir;
}

}  // namespace manisoft::test
