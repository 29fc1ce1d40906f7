// libFuzzer target: the MLP weight file (control/mlp_executor.hpp), loaded and, when it loads,
// evaluated once on a zero input.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_input.hpp"
#include "manisoft/control/mlp_executor.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = manisoft_fuzz::write_input(data, size, "weights.txt");
  return manisoft_fuzz::accept_refusal([&] {
    auto mlp = manisoft::control::Mlp<double>::load(path);
    mlp.evaluate(Eigen::VectorXd::Zero(mlp.input_size()));
  });
}
