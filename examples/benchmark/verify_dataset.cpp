// verify_dataset DIR: checks an expert dataset folder (include/manisoft/dataset/dataset_index.hpp):
// every episode file readable and complete, shapes consistent, no NaN, the index linking every
// episode, the masks covering every demo once. Exit 0 and a summary line when it is sound; exit 1
// naming the first bad file and field; exit 2 for bad flags.
#include <CLI/CLI.hpp>

#include <iostream>

#include "manisoft/dataset/dataset_index.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Checks a ManiSoft expert dataset folder (DIR/dataset.hdf5 and DIR/episodes/)"};
  std::string dir;
  app.add_option("dir", dir, "dataset folder")->required();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    const auto report = manisoft::dataset::verify_dataset(dir);
    std::cout << "verify_dataset: " << dir << ": OK: " << report.episodes << " episodes, " << report.steps
              << " steps, train " << report.train << ", valid " << report.valid;
    if (report.partial_files > 0) std::cout << " (" << report.partial_files << " partial files of an interrupted run ignored)";
    std::cout << "\n";
    return 0;
  } catch (const manisoft::Error& e) {
    std::cerr << "verify_dataset: " << e.what() << "\n";
    return 1;
  }
}
