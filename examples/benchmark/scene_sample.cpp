// scene_sample: draws one ManiSoft scene (include/manisoft/scene/scene_sampler.hpp) and writes
// its JSON (docs/scenes.md has the schema):
//   scene_sample --task COLL|ALN|STK|ARR --setting clean|randomized --index I --seed S
//                [--split train|eval] --out scene.json
// Prints the objects, obstacles, instruction and goal (scene::list_items) and the redraw count. Exit 2 on bad
// flags (CLI11 names the flag), 1 when no valid scene was found.
#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <string>

#include "../cli_checks.hpp"
#include "manisoft/scene/scene_json.hpp"
#include "manisoft/scene/scene_sampler.hpp"

namespace scene = manisoft::scene;

int main(int argc, char** argv) {
  CLI::App app{"Sample one ManiSoft scene (task, setting, index, seed) and write it as JSON"};
  std::string task = "COLL", setting = "clean", split = "train", out;
  std::uint64_t index = 0, seed = 0;
  bool quiet = false;
  app.add_option("--task", task, "COLL, ALN, STK, ARR or OVR")->required()->check(CLI::IsMember(manisoft::scene::task_names()));
  app.add_option("--setting", setting, "clean or randomized")->required()->check(CLI::IsMember({"clean", "randomized"}));
  app.add_option("--index", index, "scene index (>= 0)")->required()->check(manisoft::cli::non_negative());
  app.add_option("--seed", seed, "dataset seed (>= 0)")->required()->check(manisoft::cli::non_negative());
  app.add_option("--split", split, "train (default) or eval: disjoint seed streams")->check(CLI::IsMember({"train", "eval"}));
  app.add_option("--out", out, "scene JSON file to write")->required();
  app.add_flag("--quiet", quiet, "print nothing on success");
  manisoft::cli::readable_errors(app, "scene_sample");
  if (const int code = manisoft::cli::parse(app, argc, argv); code >= 0) return code;  // 2 after a bad flag
  try {
    scene::SampleRequest q;
    q.task = scene::parse_task(task);
    q.setting = scene::parse_setting(setting);
    q.split = scene::parse_split(split);
    q.index = index;
    q.seed = seed;
    const auto t0 = std::chrono::steady_clock::now();
    scene::SceneSampler sampler;
    const scene::SceneSpec s = sampler.sample(q);
    const double ms = 1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    scene::save_scene(out, s);
    if (!quiet) {
      std::printf("%s %s scene, split %s, index %llu, seed %llu: %zu objects, %zu obstacles, %d redraws (%.1f ms with set-up)\n", task.c_str(),
                  setting.c_str(), split.c_str(), static_cast<unsigned long long>(index), static_cast<unsigned long long>(seed), s.objects.size(),
                  s.obstacles.size(), s.sampling.redraws, ms);
      for (const auto& it : scene::list_items(s))
        std::printf("  %-8s %2d  %-20s at (%.3f, %.3f, %.3f), yaw %.1f deg\n", it.kind == scene::PlacedItem::Kind::object ? "object" : "obstacle",
                    it.index, it.asset_id.c_str(), it.position.x(), it.position.y(), it.position.z(), it.yaw * 180 / 3.14159265358979323846);
      std::printf("  instruction: %s (%zu seen + %zu unseen variants)\n", s.instruction.c_str(), s.instructions_seen.size(), s.instructions_unseen.size());
      std::printf("  goal objects:");
      for (int i : scene::goal_objects(s)) std::printf(" %d", i);
      std::printf("\nwrote %s\n", out.c_str());
    }
  } catch (const manisoft::Error& e) {
    std::fprintf(stderr, "scene_sample: %s\n", e.what());
    return 1;
  }
  return 0;
}
