// verify_dataset DIR [--replay [--sample N]]: checks an expert dataset folder
// (include/manisoft/dataset/): every episode file readable and complete, its whole schema
// (dataset/expert_schema.hpp: every dataset and attribute, dtypes, shapes, actions within the
// actuation limits, S, dones, rewards, success, the scene attribute and the task it names), its
// content digest (dataset/episode_digest.hpp), the index linking every episode with the run's
// arguments, the masks covering every demo once. --replay re-simulates every episode (--sample N:
// N of them, evenly spaced in index order) from its scene and actions through the task
// environment (dataset::replay_mismatch) and names the first step and state field that differ.
// Exit 0 and a summary line when it is sound; exit 1 naming the first bad file, field, element
// and rule; exit 2 for bad flags.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "../cli_checks.hpp"
#include "manisoft/dataset/expert_schema.hpp"
#include "manisoft/scene/asset_library.hpp"

namespace ds = manisoft::dataset;
namespace fs = std::filesystem;

namespace {

/// What column `c` of a state row is (expert_recording.hpp's layout: rod nodes, object poses,
/// finger width, S).
std::string state_field(int c, int elements, int objects) {
  static const std::array<const char*, 7> pose{"x", "y", "z", "qw", "qx", "qy", "qz"};
  const int rod = 3 * (elements + 1), poses = rod + 7 * objects;
  if (c < rod) return "rod node " + std::to_string(c / 3) + " " + pose[static_cast<std::size_t>(c % 3)];
  if (c < poses) return "object " + std::to_string((c - rod) / 7) + " " + pose[static_cast<std::size_t>((c - rod) % 7)];
  return c == poses ? "finger width" : "S";
}

/// Replays episode k of `file`; "" when every state and the success match, else what differs.
std::string replay_difference(manisoft::task::TaskEnv& env, const fs::path& file, long k) {
  const ds::Episode e = ds::read_episode(file, k);
  const long r = ds::replay_mismatch(env, e);
  const std::string at = file.string() + ": " + ds::demo_path(k) + ": replay: ";
  if (r < 0) {
    const double recorded = e.numbers.at("success");
    if (recorded != (env.info().success ? 1.0 : 0.0))
      return at + "attribute 'success' = " + std::to_string(recorded) + " but the replayed episode " + (env.info().success ? "succeeds" : "fails");
    return "";
  }
  if (r == e.steps()) return at + "the recording ends after " + std::to_string(r) + " steps but the replayed episode goes on";
  Eigen::RowVectorXd state(e.states.cols());
  ds::read_state(env, state);
  const int elements = env.arm_model().rod.n_elements, objects = static_cast<int>(env.spec().objects.size());
  for (int c = 0; c < state.size(); ++c) {
    if (state(c) == e.states(r, c)) continue;
    const std::string field = state_field(c, elements, objects);
    std::ostringstream out;
    out.precision(17);
    out << at << "first differing step " << r << ": states [" << r << ", " << c << "] (" << field << ") recorded " << e.states(r, c)
        << ", replayed " << state(c) << " (the action of step " << r - 1 << " or earlier differs from what was simulated)";
    return out.str();
  }
  return at + "the replayed episode ended at step " + std::to_string(r) + " (" + (env.info().success ? "success" : "failure") +
         ") but the recording goes on to step " + std::to_string(e.steps() - 1);
}

/// The demos to replay: all, or `sample` of them evenly spaced in index order.
std::vector<long> replay_choice(const fs::path& dir, long sample) {
  const ds::h5::File index = ds::h5::File::open(ds::index_file(dir).string());
  std::vector<long> all;
  for (const std::string& demo : index.children("/data")) all.push_back(std::stol(demo.substr(5)));  // names checked by verify
  std::sort(all.begin(), all.end());
  if (sample <= 0 || sample >= static_cast<long>(all.size())) return all;
  std::vector<long> chosen;
  for (long i = 0; i < sample; ++i) chosen.push_back(all[static_cast<std::size_t>(i * static_cast<long>(all.size()) / sample)]);
  return chosen;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Checks a ManiSoft expert dataset folder (DIR/dataset.hdf5 and DIR/episodes/)"};
  std::string dir;
  bool replay = false;
  long sample = 0;
  app.add_option("dir", dir, "dataset folder")->required();
  app.add_flag("--replay", replay, "re-simulate the episodes from their scenes and actions; name the first differing step");
  app.add_option("--sample", sample, "with --replay: replay N episodes, evenly spaced in index order (default: all)")
      ->check(manisoft::cli::at_least(1));
  manisoft::cli::readable_errors(app, "verify_dataset");
  if (const int code = manisoft::cli::parse(app, argc, argv); code >= 0) return code;  // 2 after a bad flag
  try {
    if (sample > 0 && !replay) manisoft::detail::fail("--sample ", sample, " needs --replay");
    const auto report = ds::verify_dataset(dir, ds::check_expert_episode);
    std::ostringstream summary;
    summary << "verify_dataset: " << dir << ": OK: " << report.episodes << " episodes, " << report.steps << " steps, train "
            << report.train << ", valid " << report.valid;
    if (report.partial_files > 0) summary << " (" << report.partial_files << " partial files of an interrupted run ignored)";
    if (replay) {
      const manisoft::scene::AssetLibrary library;
      manisoft::task::TaskEnv env(library);
      const std::vector<long> chosen = replay_choice(dir, sample);
      for (long k : chosen)
        if (const std::string difference = replay_difference(env, ds::episode_file(dir, k), k); !difference.empty())
          manisoft::detail::fail(difference);
      summary << "; " << chosen.size() << " episodes replayed bit for bit";
    }
    std::cout << summary.str() << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "verify_dataset: " << e.what() << "\n";
    return 1;
  }
}
