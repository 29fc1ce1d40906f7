// Shared by the libFuzzer targets in this folder: the fuzzer's bytes written to a file of this
// process's own scratch folder (for readers that take a path), and the rule every target follows:
// a manisoft::Error (the readers' documented refusal) is a normal outcome; anything else escaping
// the reader (another exception, a crash, a sanitizer report, a hang) is a finding.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "manisoft/core/error.hpp"

namespace manisoft_fuzz {

/// A scratch folder of this process (parallel fuzzer jobs do not share files); removed at exit.
inline const std::filesystem::path& scratch() {
  struct Folder {
    std::filesystem::path path = std::filesystem::temp_directory_path() / ("manisoft_fuzz_" + std::to_string(::getpid()));
    Folder() { std::filesystem::create_directories(path); }
    ~Folder() {
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
  };
  static const Folder folder;
  return folder.path;
}

/// Writes the input to scratch()/name and returns that path.
inline std::string write_input(const std::uint8_t* data, std::size_t size, const std::string& name) {
  const std::filesystem::path path = scratch() / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path.string();
}

/// Runs `read`, treating manisoft::Error as the reader's documented refusal of a bad input.
template <typename Read>
int accept_refusal(Read&& read) {
  try {
    read();
  } catch (const manisoft::Error&) {
  }
  return 0;
}

}  // namespace manisoft_fuzz
