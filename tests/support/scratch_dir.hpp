// A scratch folder for one test process: ctest runs test cases of the same program in parallel
// (one process each), so a folder shared by name would let one case read another's files.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

namespace manisoft::test {

/// `<temp>/<name>_<pid>`, created if missing.
inline std::filesystem::path scratch_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / (name + "_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace manisoft::test
