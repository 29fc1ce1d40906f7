// The rod_sim command-line tool, run as a user scripts it: reproduces a reference CSV through its
// flags, and refuses bad flags with exit code 2 and a message.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "../support/command_line.hpp"
#include "../support/scratch_dir.hpp"

namespace {

using manisoft::test::read_csv;
using manisoft::test::slurp;

int run(const std::string& arguments, const std::string& log) { return manisoft::test::run_command(MANISOFT_ROD_SIM, arguments, log); }

const std::string scratch = manisoft::test::scratch_dir("manisoft_rod_sim_test").string();

}  // namespace

TEST_CASE("rod_sim reproduces b_torque20_lab_n20 through its command line", "[rod][rod_sim]") {
  std::filesystem::create_directories(scratch);
  const std::string out = scratch + "/b20.csv";
  REQUIRE(run("--n 20 --dt 2e-4 --t-end 2 --record-every 0.01 --damping analytical:0.1 --lab-torque 20,0,-1,0 --out " + out,
              scratch + "/log.txt") == 0);
  CHECK_THAT(slurp(scratch + "/log.txt"), Catch::Matchers::Contains("steps/s"));
  std::string header, reference_header;
  const auto ours = read_csv(out, header);
  const auto reference = read_csv(std::string(MANISOFT_TEST_DATA_DIR) + "/pyelastica/b_torque20_lab_n20.csv", reference_header);
  CHECK(header == reference_header);
  REQUIRE(ours.size() == reference.size());
  double worst = 0;
  for (std::size_t r = 0; r < ours.size(); ++r)
    for (std::size_t c = 0; c < 13; ++c) worst = std::max(worst, std::abs(ours[r][c] - reference[r][c]));
  CHECK(worst < 1e-6);
}

TEST_CASE("rod_sim refuses bad flags with exit code 2 and says why", "[rod][rod_sim]") {
  std::filesystem::create_directories(scratch);
  const std::string log = scratch + "/bad.txt";
  CHECK(run("--n 20 --out " + scratch + "/x.csv --damping viscous:3", log) == 2);
  CHECK_THAT(slurp(log), Catch::Matchers::Contains("--damping must be none, analytical:NU or uniform:GAMMA"));
  CHECK(run("--n 20 --lab-torque 1,2 --out " + scratch + "/x.csv", log) == 2);
  CHECK_THAT(slurp(log), Catch::Matchers::Contains("--lab-torque expects 4"));
  CHECK(run("--n 20 --dt abc --out " + scratch + "/x.csv", log) == 2);
  CHECK(run("--n 20", log) == 2);
  CHECK_THAT(slurp(log), Catch::Matchers::Contains("--out is required"));
  CHECK(run("--n 20 --frobnicate --out " + scratch + "/x.csv", log) == 2);
  // A configuration the library refuses: exit 1 and the library's message.
  CHECK(run("--n 50 --dt 2e-4 --out " + scratch + "/x.csv", log) == 1);
  CHECK_THAT(slurp(log), Catch::Matchers::Contains("stability limit"));
}
