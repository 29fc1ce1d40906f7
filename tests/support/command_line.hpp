// Helpers for tests that run the command-line tools as a user scripts them: run a binary with
// arguments (stdout and stderr into a log file) and read its numeric CSV output.
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

namespace manisoft::test {

/// Runs `binary arguments > log 2>&1`; returns the exit code (-1 if it did not exit normally).
inline int run_command(const std::string& binary, const std::string& arguments, const std::string& log) {
  const std::string command = binary + " " + arguments + " > " + log + " 2>&1";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

inline std::string slurp(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

/// A CSV of numbers with one header line: the rows, and the header through `header`.
inline std::vector<std::vector<double>> read_csv(const std::string& path, std::string& header) {
  std::ifstream in(path);
  std::getline(in, header);
  std::vector<std::vector<double>> rows;
  std::string line;
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::stringstream cells(line);
    std::string cell;
    while (std::getline(cells, cell, ',')) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  return rows;
}

}  // namespace manisoft::test
