// generate_dataset: the expert dataset (paper section 3.5) as robomimic-layout HDF5 files
// (include/manisoft/dataset/: one file an episode under DIR/episodes/, the index DIR/dataset.hdf5).
//
//   generate_dataset --tasks COLL,ALN,STK,ARR --clean N --randomized M --seed S --out DIR
//                    [--shard i/n] [--resume] [--images none|every:K] [--image-size W H] [--jobs J]
//                    [--max-draws A] [--index-only]
//
// Episode k (0 <= k < N + M) is a pure function of (seed, k): clean for k < N, randomized after;
// within a setting, the tasks take turns (j-th episode of the setting: task j mod T, its
// (j div T)-th of that task). Its scene is train-split scene index (j div T) * A + a for draw
// a = 0, 1, ...: the first draw whose expert episode succeeds is kept (the paper's quality check:
// only successful expert episodes), the others are redrawn and counted with their reason. Images
// (--images every:K) are rendered while the kept episode's actions replay, so failed draws cost
// physics only. So the
// same dataset comes out as one shard or as n shards (--shard i/n takes k = i, i + n, ...), with
// any --jobs: file for file, bit for bit.
// Atomic and resumable: an episode is written under a temporary name and renamed when complete;
// --resume skips complete episodes (a killed run loses only the episodes in flight). Each episode
// records the run's arguments (attribute generate_args, the index's env_args): a run whose
// arguments differ from those recorded in DIR is refused before anything is written, naming each
// differing flag with both values. When every
// episode of the dataset is there, the index is written (--index-only: only that, the merge step
// after a sharded run; it names the first missing episode). Progress on stderr: a bar on a
// terminal, plain lines otherwise. Exit 0 on success, 1 on an error, 2 on bad flags.
#include <CLI/CLI.hpp>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "../cli_checks.hpp"
#include "episode_images.hpp"
#include "manisoft/dataset/dataset_index.hpp"
#include "manisoft/dataset/expert_recording.hpp"
#include "manisoft/scene/scene_sampler.hpp"
#include "manisoft/task/expert.hpp"

namespace fs = std::filesystem;
namespace ms = manisoft;

namespace {

struct Plan {
  std::vector<ms::scene::Task> tasks;
  long clean = 0, randomized = 0;
  std::uint64_t seed = 0;
  int max_draws = 100;
  int image_every = 0;  // 0: no images
  int image_width = 128, image_height = 128;

  long total() const { return clean + randomized; }
  /// Task, setting and the first scene index of episode k.
  ms::scene::SampleRequest request(long k) const {
    const bool is_clean = k < clean;
    const long j = is_clean ? k : k - clean;
    const long t = static_cast<long>(tasks.size());
    ms::scene::SampleRequest q;
    q.task = tasks[static_cast<std::size_t>(j % t)];
    q.setting = is_clean ? ms::scene::Setting::clean : ms::scene::Setting::randomized;
    q.split = ms::scene::Split::train;
    q.index = static_cast<std::uint64_t>(j / t) * static_cast<std::uint64_t>(max_draws);
    q.seed = seed;
    return q;
  }
  std::string env_args() const {
    nlohmann::json j;
    j["env_name"] = "ManiSoft";
    j["type"] = "manisoft";
    std::vector<std::string> names;
    for (auto t : tasks) names.emplace_back(ms::scene::to_string(t));
    const ms::task::TaskEnvConfig env;  // the episodes' horizon and control step
    j["env_kwargs"] = {{"tasks", names},       {"clean", clean},  {"randomized", randomized}, {"seed", seed},
                       {"max_draws", max_draws}, {"horizon", env.horizon}, {"control_dt", env.dt * env.substeps},    {"image_every", image_every},
                       {"image_width", image_width}, {"image_height", image_height}};
    return j.dump();
  }
};

/// One worker: its own sampler, environment, expert (and renderer when images are asked for).
class Worker {
 public:
  explicit Worker(const Plan& plan)
      : plan_(plan), env_(sampler_.library()), expert_(env_), images_(plan.image_width, plan.image_height) {}

  /// The kept episode k, and the reasons of the draws redrawn before it.
  ms::dataset::Episode make(long k, std::map<std::string, long>& redraw_reasons) {
    ms::scene::SampleRequest q = plan_.request(k);
    const std::uint64_t first = q.index;
    for (int a = 0; a < plan_.max_draws; ++a) {
      q.index = first + static_cast<std::uint64_t>(a);
      const ms::scene::SceneSpec spec = sampler_.sample(q);
      env_.reset(spec);
      expert_.reset();
      ms::dataset::EpisodeRecorder recorder(env_);
      ms::task::TaskEnv::Array3 torques;
      int s = 0;
      // A draw ends when the episode does or when the expert gives up: an episode it no longer
      // drives is not kept, so its remaining steps until the horizon would be spent for nothing.
      while (!env_.done() && !expert_.failure()) {
        expert_.act(torques, s);
        recorder.step(torques, s, expert_.target());
        env_.step(torques, s);
      }
      if (env_.info().success) {
        ms::dataset::Episode e = recorder.finish(k, plan_.seed, a);
        e.text[std::string(ms::dataset::generate_args_attribute)] = plan_.env_args();
        if (plan_.image_every > 0) e.images["agentview_image"] = images_.render(env_, spec, e, plan_.image_every);
        return e;
      }
      const std::string why = expert_.failure() ? "expert: " + std::string(*expert_.failure()) : std::string(ms::task::to_string(env_.info().failure));
      ++redraw_reasons[std::string(ms::scene::to_string(q.task)) + " " + why.substr(0, 60)];
    }
    ms::detail::fail("episode ", k, ": no successful expert episode in ", plan_.max_draws, " draws (", ms::scene::to_string(q.task), " ",
                     ms::scene::to_string(q.setting), ", scene indices ", first, "..", first + plan_.max_draws - 1, "): raise --max-draws");
  }

 private:
  const Plan& plan_;
  ms::scene::SceneSampler sampler_;
  ms::task::TaskEnv env_;
  ms::task::Expert expert_;
  manisoft_examples::EpisodeImages images_;  // rendered while a kept episode's actions replay: failed draws cost physics only
};

/// The flag (or library setting) behind a key of the recorded generation arguments.
std::string flag_of(const std::string& key) {
  static const std::map<std::string, std::string> flags{{"tasks", "--tasks"}, {"clean", "--clean"}, {"randomized", "--randomized"},
                                                        {"seed", "--seed"}, {"max_draws", "--max-draws"}, {"image_every", "--images (every:K)"},
                                                        {"image_width", "--image-size (W)"}, {"image_height", "--image-size (H)"}};
  const auto it = flags.find(key);
  return it != flags.end() ? it->second : key + " (the library's TaskEnvConfig)";
}

/// Refuses to add to a dataset generated with other arguments than this run's: compares them with
/// those recorded in every complete episode file and in the index (if any), naming each differing
/// argument with both values. Runs before anything is written.
void require_recorded_arguments(const fs::path& dir, const Plan& plan) {
  const nlohmann::json asked = nlohmann::json::parse(plan.env_args()).at("env_kwargs");
  const auto compare = [&](const std::string& where, const std::string& recorded_text) {
    const nlohmann::json recorded = nlohmann::json::parse(recorded_text, nullptr, false);
    if (!recorded.is_object() || !recorded.contains("env_kwargs"))
      ms::detail::fail(where, ": its recorded generation arguments are not readable: cannot add to it safely; use another --out");
    std::string differences;
    for (const auto& [key, value] : asked.items()) {
      const auto& kwargs = recorded["env_kwargs"];
      const std::string was = kwargs.contains(key) ? kwargs[key].dump() : "(not recorded)";
      if (was != value.dump()) differences += (differences.empty() ? "" : ", ") + flag_of(key) + " is " + value.dump() + " here, " + was + " there";
    }
    if (!differences.empty())
      ms::detail::fail(where, " was generated with other arguments: ", differences, ". Run with the recorded arguments, or use another --out");
  };
  for (long k : ms::dataset::complete_episodes(dir)) {
    const ms::dataset::h5::File f = ms::dataset::h5::File::open(ms::dataset::episode_file(dir, k).string());
    const auto names = f.attribute_names(ms::dataset::demo_path(k));
    if (std::find(names.begin(), names.end(), ms::dataset::generate_args_attribute) == names.end())
      ms::detail::fail(f.name(), ": records no generation arguments (an older generate_dataset wrote it): cannot add to it safely; use another --out");
    compare(f.name(), f.read_string_attribute(ms::dataset::demo_path(k), ms::dataset::generate_args_attribute));
  }
  if (fs::exists(ms::dataset::index_file(dir))) {
    const ms::dataset::h5::File index = ms::dataset::h5::File::open(ms::dataset::index_file(dir).string());
    compare(index.name(), index.read_string_attribute("/data", "env_args"));
  }
}

std::vector<ms::scene::Task> parse_tasks(const std::string& list) {
  std::vector<ms::scene::Task> out;
  std::stringstream in(list);
  std::string name;
  while (std::getline(in, name, ',')) out.push_back(ms::scene::parse_task(name));
  if (out.empty()) ms::detail::fail("--tasks: no task given");
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Generate the ManiSoft expert dataset (robomimic-layout HDF5)"};
  std::string tasks = "COLL,ALN,STK,ARR", out, shard = "0/1", images = "none";
  Plan plan;
  int jobs = 1;
  bool resume = false, index_only = false;
  std::vector<int> image_size{128, 128};
  app.add_option("--tasks", tasks, "comma-separated tasks (COLL, ALN, STK, ARR)");
  app.add_option("--clean", plan.clean, "clean-scene episodes in all");
  app.add_option("--randomized", plan.randomized, "randomized-scene episodes in all");
  app.add_option("--seed", plan.seed, "dataset seed");
  app.add_option("--out", out, "dataset folder")->required();
  app.add_option("--shard", shard, "i/n: this process makes the episodes k with k mod n = i");
  app.add_flag("--resume", resume, "skip episodes whose files are complete");
  app.add_option("--images", images, "none, or every:K (a camera image every K control steps)");
  app.add_option("--image-size", image_size, "W H of the images")->expected(2)->check(manisoft::cli::positive());
  app.add_option("--jobs", jobs, "worker threads")->check(CLI::Range(1, 256));
  app.add_option("--max-draws", plan.max_draws, "scene draws per episode before giving up")->check(CLI::Range(1, 100000));
  app.add_flag("--index-only", index_only, "only write the index (after every shard is done)");
  manisoft::cli::check_counts(app, {"--clean", "--randomized", "--seed"});
  manisoft::cli::readable_errors(app, "generate_dataset");
  if (const int code = manisoft::cli::parse(app, argc, argv); code >= 0) return code;  // 2 after a bad flag
  try {
    plan.tasks = parse_tasks(tasks);
    long shard_i = 0, shard_n = 1;
    if (std::sscanf(shard.c_str(), "%ld/%ld", &shard_i, &shard_n) != 2 || shard_n < 1 || shard_i < 0 || shard_i >= shard_n)
      ms::detail::fail("--shard '", shard, "': expected i/n with 0 <= i < n");
    if (images != "none") {
      if (images.rfind("every:", 0) != 0 || std::sscanf(images.c_str() + 6, "%d", &plan.image_every) != 1 || plan.image_every < 1)
        ms::detail::fail("--images '", images, "': expected none or every:K with K >= 1");
    }
    plan.image_width = image_size[0];
    plan.image_height = image_size[1];
    if (plan.total() < 1) ms::detail::fail("--clean + --randomized must be at least 1");
    const fs::path dir = out;
    require_recorded_arguments(dir, plan);
    fs::create_directories(ms::dataset::episode_folder(dir));
    if (!index_only) {
      std::vector<long> todo;
      for (long k = shard_i; k < plan.total(); k += shard_n) {
        const fs::path f = ms::dataset::episode_file(dir, k);
        if (resume && fs::exists(f)) continue;
        if (!resume && fs::exists(f)) ms::detail::fail(f.string(), " exists: use --resume to continue a run, or another --out");
        todo.push_back(k);
      }
      const bool tty = isatty(fileno(stderr));
      std::fprintf(stderr, "generate_dataset: %zu episodes to make (shard %ld/%ld of %ld), %d job(s)\n", todo.size(), shard_i, shard_n,
                   plan.total(), jobs);
      std::atomic<std::size_t> next{0};
      std::mutex mutex;  // HDF5 writes, the report, progress
      std::map<std::string, long> reasons;
      long done = 0, redraws = 0;
      std::string error;
      const auto t0 = std::chrono::steady_clock::now();
      auto work = [&] {
        try {
          Worker worker(plan);
          for (std::size_t i; (i = next++) < todo.size();) {
            std::map<std::string, long> local;
            const ms::dataset::Episode e = worker.make(todo[i], local);
            std::lock_guard lock(mutex);
            if (!error.empty()) return;
            ms::dataset::write_episode(ms::dataset::episode_file(dir, todo[i]), e);
            for (const auto& [r, c] : local) reasons[r] += c, redraws += c;
            ++done;
            const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            const double rate = done / s;
            const double left = (static_cast<double>(todo.size()) - done) / rate;
            if (tty) {
              const int width = 30, filled = static_cast<int>(width * done / static_cast<long>(todo.size()));
              std::fprintf(stderr, "\r[%s%s] %ld/%zu episodes, %ld redrawn, %.2f episodes/s, %.0f s left   ", std::string(filled, '#').c_str(),
                           std::string(width - filled, '.').c_str(), done, todo.size(), redraws, rate, left);
            } else {
              std::fprintf(stderr, "episode %ld: %s %s, %ld steps, %d redrawn; %ld/%zu done, %.2f episodes/s, %.0f s left\n", todo[i],
                           e.text.at("task").c_str(), e.text.at("setting").c_str(), e.steps(), static_cast<int>(e.numbers.at("redraws")), done,
                           todo.size(), rate, left);
            }
          }
        } catch (const std::exception& ex) {
          std::lock_guard lock(mutex);
          if (error.empty()) error = ex.what();
          next = todo.size();
        }
      };
      std::vector<std::thread> threads;
      for (int j = 1; j < jobs; ++j) threads.emplace_back(work);
      work();
      for (auto& t : threads) t.join();
      if (tty) std::fprintf(stderr, "\n");
      if (!error.empty()) ms::detail::fail(error);
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::printf("generate_dataset: %ld episodes written in %.1f s (%.2f episodes/s); %ld failed expert draws redrawn\n", done, s, done / s, redraws);
      for (const auto& [r, c] : reasons) std::printf("  redrawn %5ld x  %s\n", c, r.c_str());
    }
    const auto complete = ms::dataset::complete_episodes(dir);
    if (static_cast<long>(complete.size()) == plan.total() || index_only) {
      ms::dataset::write_index(dir, plan.env_args(), plan.total());
      std::printf("generate_dataset: index %s over %ld episodes\n", ms::dataset::index_file(dir).string().c_str(), plan.total());
    } else {
      std::printf("generate_dataset: %zu of %ld episodes complete; the index is written once all are (or run --index-only after the shards)\n",
                  complete.size(), plan.total());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "generate_dataset: %s\n", e.what());
    return 1;
  }
  return 0;
}
