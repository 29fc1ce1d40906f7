// Camera images of a recorded episode, rendered while its actions replay in a TaskEnv (the replay
// is exact, so the images are those of the original run): generate_dataset (--images every:K)
// and render_dataset ("physics first, images later") share it. Any render::Renderer backend
// reading colour only (EpisodeImages: render::GlRenderer, OpenGL through EGL) or Blender (one
// headless process per episode, rendering all of its frames: examples/render/blender_run.hpp),
// the scene drawn as scene::make_render_scene (manisoft/scene/scene_render.hpp) makes it.
#pragma once

#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "../render/blender_run.hpp"
#include "manisoft/control/action_layout.hpp"
#include "manisoft/dataset/episode.hpp"
#include "manisoft/render/gl_renderer.hpp"
#include "manisoft/render/renderer.hpp"
#include "manisoft/scene/scene_render.hpp"
#include "manisoft/task/task_env.hpp"

namespace manisoft_examples {

template <manisoft::render::Renderer R>
class BasicEpisodeImages {
 public:
  /// `camera`: the view (its width and height are the images'); unset: each scene's own camera
  /// at width x height. `blender`: render with Blender instead of R, in `blender_dir`
  /// (scratch: the exported scene and the PNG frames of the episode being rendered).
  BasicEpisodeImages(int width, int height, std::optional<manisoft::render::Camera> camera = std::nullopt,
                     std::optional<manisoft::render::blender::RunOptions> blender = std::nullopt, std::filesystem::path blender_dir = {})
      : width_(width), height_(height), camera_(camera), blender_(blender), blender_dir_(std::move(blender_dir)) {}

  /// Replays `e` (actions) from `spec` in `env`, an image every `every` control steps from step 0.
  manisoft::dataset::ImageSequence render(manisoft::task::TaskEnv& env, const manisoft::scene::SceneSpec& spec, const manisoft::dataset::Episode& e,
                                          int every) {
    manisoft::dataset::ImageSequence images;
    images.width = width_;
    images.height = height_;
    set_scene(spec, env.library());
    env.reset(spec);
    const int n = static_cast<int>(e.actions.cols() - 1) / 3;  // FlatAction::size(n) columns
    manisoft::task::TaskEnv::Array3 torques(n, 3);
    frames_.clear();
    for (long r = 0; r < e.steps(); ++r) {
      if (r % every == 0) add_image(env, images, r);
      const int s = manisoft::control::FlatAction::unpack(e.actions.row(r), torques);
      env.step(torques, s);
    }
    if (blender_) render_with_blender(images);
    return images;
  }

 private:
  void set_scene(const manisoft::scene::SceneSpec& spec, const manisoft::scene::AssetLibrary& library) {
    if (!renderer_ && !blender_) renderer_ = manisoft::render::make_colour_renderer<R>();
    scene_ = manisoft::scene::make_render_scene(spec, library);
    manisoft::render::Camera camera = camera_ ? *camera_ : spec.cameras.front();
    camera.width = width_;
    camera.height = height_;
    scene_.scene.cameras = {camera};
    if (renderer_) renderer_->set_scene(scene_.scene);
  }

  void add_image(const manisoft::task::TaskEnv& env, manisoft::dataset::ImageSequence& images, long step) {
    const auto& w = env.world();
    const manisoft::math::Pose<double> gripper{w.rigid().orientation(w.gripper_body()).toRotationMatrix(), w.rigid().position(w.gripper_body())};
    objects_.clear();
    for (const auto b : env.bodies().objects) objects_.push_back({w.rigid().orientation(b).toRotationMatrix(), w.rigid().position(b)});
    const manisoft::render::FrameState frame =
        manisoft::scene::render_frame(scene_, w.rod().state().positions, gripper, w.gripper().finger_width(), objects_);
    images.steps.push_back(step);
    ++images.frames;
    if (blender_) {
      frames_.push_back(frame);
      return;
    }
    renderer_->render_into(frame, out_);
    images.pixels.insert(images.pixels.end(), out_.rgb.begin(), out_.rgb.end());
  }

  // All frames of the episode in one Blender process, then their PNGs into `images`.
  void render_with_blender(manisoft::dataset::ImageSequence& images) {
    std::filesystem::remove_all(blender_dir_);
    manisoft::render::blender::render_frames(scene_.scene, frames_, blender_dir_, *blender_);
    for (std::size_t k = 0; k < frames_.size(); ++k) {
      char name[32];
      std::snprintf(name, sizeof name, "rgb_%05zu.png", k);
      const manisoft::render::RgbImage rgb = manisoft::render::read_png_rgb(blender_dir_ / name);
      if (rgb.width != width_ || rgb.height != height_)
        manisoft::detail::fail("blender frame ", (blender_dir_ / name).string(), " is ", rgb.width, " x ", rgb.height, ", expected ", width_, " x ", height_);
      images.pixels.insert(images.pixels.end(), rgb.rgb.begin(), rgb.rgb.end());
    }
  }

  int width_, height_;
  std::optional<manisoft::render::Camera> camera_;
  std::optional<manisoft::render::blender::RunOptions> blender_;
  std::filesystem::path blender_dir_;
  std::vector<manisoft::render::FrameState> frames_;  // Blender: the episode's frames, rendered at its end
  std::unique_ptr<R> renderer_;
  manisoft::render::tabletop::TabletopScene scene_;
  manisoft::render::RenderOutput out_;
  std::vector<manisoft::math::Pose<double>> objects_;
};

/// Episode images drawn with the in-process OpenGL renderer (or Blender).
using EpisodeImages = BasicEpisodeImages<manisoft::render::GlRenderer>;

}  // namespace manisoft_examples
