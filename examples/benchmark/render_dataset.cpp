// render_dataset: camera images for a dataset generated with states only ("physics first, images
// later"). Each episode's actions replay exactly from its scene (TaskEnv is
// deterministic), and an image is rendered every K control steps, at any resolution and camera:
//
//   render_dataset DIR --out OUT [--every K] [--image-size W H] [--episodes K,...]
//                  [--camera-position X Y Z --look-at X Y Z --fov-y DEG]
//                  [--renderer gl|blender [--engine workbench|cycles] [--samples N]]
//
// writes OUT/demo_<k>.hdf5 with /data/demo_<k>/images/agentview_image (uint8 F x H x W x 3, gzip,
// one chunk a frame) and agentview_image_steps (int64 F), the episode files' own layout, each
// written atomically (a killed run leaves only *.partial files; complete files are skipped on a
// rerun). Without camera flags each scene's camera is used. `--renderer blender` renders each
// episode's frames in one headless Blender process (the paper's look; Workbench about 0.2 s and
// Cycles seconds a frame) in the scratch folder OUT/blender.partial, removed at the end.
// Exit 0 on success, 1 on an error (naming the file), 2 on bad flags.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "../cli_checks.hpp"
#include "episode_images.hpp"
#include "manisoft/dataset/dataset_index.hpp"
#include "manisoft/scene/scene_json.hpp"
#include "manisoft/scene/scene_sampler.hpp"

namespace fs = std::filesystem;
namespace ms = manisoft;

int main(int argc, char** argv) {
  CLI::App app{"Render camera images for a ManiSoft dataset by replaying its episodes"};
  std::string dir, out, renderer = "gl", engine = "workbench";
  int every = 10, samples = 16;
  std::vector<int> size{514, 514};
  std::vector<double> position, look_at;
  std::vector<long> only;
  double fov = 60.0;
  app.add_option("dir", dir, "dataset folder")->required()->check(CLI::ExistingDirectory);
  app.add_option("--out", out, "output folder")->required();
  app.add_option("--every", every, "an image every K control steps")->check(manisoft::cli::positive());
  app.add_option("--image-size", size, "W H")->expected(2)->check(manisoft::cli::positive());
  app.add_option("--episodes", only, "only these episode indices (default: all)")->delimiter(',')->check(manisoft::cli::non_negative());
  auto* p = app.add_option("--camera-position", position, "camera position X Y Z (m, world frame)")->expected(3);
  app.add_option("--look-at", look_at, "point at the image centre X Y Z (m)")->expected(3)->needs(p);
  app.add_option("--fov-y", fov, "vertical field of view, degrees")->needs(p);
  app.add_option("--renderer", renderer, "gl (in-process OpenGL, default) or blender")->check(CLI::IsMember({"gl", "blender"}));
  app.add_option("--engine", engine, "blender: workbench or cycles")->check(CLI::IsMember({"workbench", "cycles"}));
  app.add_option("--samples", samples, "blender: Cycles samples")->check(manisoft::cli::between(1, 4096));
  manisoft::cli::readable_errors(app, "render_dataset");
  if (const int code = manisoft::cli::parse(app, argc, argv); code >= 0) return code;  // 2 after a bad flag
  try {
    std::optional<ms::render::Camera> camera;
    if (!position.empty()) {
      if (look_at.empty()) ms::detail::fail("--camera-position needs --look-at");
      ms::render::Camera c;
      c.position = {position[0], position[1], position[2]};
      c.look_at = {look_at[0], look_at[1], look_at[2]};
      c.fov_y_deg = fov;
      c.width = size[0];
      c.height = size[1];
      ms::render::validate(c);
      camera = c;
    }
    ms::scene::SceneSampler sampler;  // its asset library
    ms::task::TaskEnv env(sampler.library());
    std::optional<ms::render::blender::RunOptions> blender;
    if (renderer == "blender") blender = ms::render::blender::RunOptions{engine, samples, false};
    const fs::path blender_dir = fs::path(out) / "blender.partial";
    manisoft_examples::EpisodeImages images(size[0], size[1], camera, blender, blender_dir);
    fs::create_directories(out);
    const auto t0 = std::chrono::steady_clock::now();
    long done = 0, frames = 0;
    const std::vector<long> complete = ms::dataset::complete_episodes(dir);
    for (const long k : only)
      if (std::find(complete.begin(), complete.end(), k) == complete.end()) ms::detail::fail("--episodes: episode ", k, " is not a complete episode of ", dir);
    for (const long k : complete) {
      if (!only.empty() && std::find(only.begin(), only.end(), k) == only.end()) continue;
      const fs::path target = fs::path(out) / ("demo_" + std::to_string(k) + ".hdf5");
      if (fs::exists(target)) continue;
      const fs::path source = ms::dataset::episode_file(dir, k);
      const ms::dataset::Episode e = ms::dataset::read_episode(source, k);
      const auto scene = e.text.find("scene");
      if (scene == e.text.end()) ms::detail::fail(source.string(), ": no scene attribute");
      const ms::scene::SceneSpec spec = ms::scene::parse_scene(scene->second, source.string() + " scene");
      const ms::dataset::ImageSequence seq = images.render(env, spec, e, every);
      const fs::path partial = target.string() + ms::dataset::partial_suffix;
      {
        ms::dataset::h5::File f = ms::dataset::h5::File::create(partial.string());
        const std::string group = ms::dataset::demo_path(k) + "/images";
        f.create_groups(group);
        f.write(group + "/agentview_image",
                {static_cast<hsize_t>(seq.frames), static_cast<hsize_t>(seq.height), static_cast<hsize_t>(seq.width), 3}, seq.pixels.data(), 4);
        f.write(group + "/agentview_image_steps", {static_cast<hsize_t>(seq.frames)}, seq.steps.data());
        f.close();
      }
      fs::rename(partial, target);
      ++done;
      frames += seq.frames;
      std::fprintf(stderr, "demo_%ld: %d frames of %d x %d\n", k, seq.frames, seq.width, seq.height);
    }
    fs::remove_all(blender_dir);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("render_dataset: %ld episodes, %ld frames in %.1f s -> %s\n", done, frames, s, out.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "render_dataset: %s\n", e.what());
    return 1;
  }
  return 0;
}
