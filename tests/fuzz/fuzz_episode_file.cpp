// libFuzzer target: an episode file of the expert dataset (dataset/episode_file.hpp, HDF5) opened
// and read as episode 0, then its content digest checked (dataset/dataset_index.hpp).
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_input.hpp"
#include "manisoft/dataset/dataset_index.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = manisoft_fuzz::write_input(data, size, "demo_0.hdf5");
  return manisoft_fuzz::accept_refusal([&] {
    const manisoft::dataset::Episode episode = manisoft::dataset::read_episode(path, 0);
    manisoft::dataset::check_digest(path, episode);
  });
}
