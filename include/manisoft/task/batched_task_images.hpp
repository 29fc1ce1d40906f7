// BatchedTaskImages: the camera image of every arm of a task::BatchedTaskEnv (the image V_t a policy
// sees, ManiSoft paper section 3.2), drawn on the batch's own worker threads: each arm's frame is
// rendered right after its reset or step, on the thread that ran it (BatchedTaskEnv's arm
// observer), so the frames are drawn in parallel as the physics is.
//
//   BatchedTaskEnv batch(B, threads, settings);
//   BatchedTaskImages images(batch, 128, 128);   // before the first reset; each scene's camera at 128 x 128
//   batch.reset(indices);  batch.step(actions);
//   images.images()                              // B x H x W x 3 uint8, row-major, top row first
//
// Camera: unset, each scene's own first camera at width x height; set, that camera (its width and
// height replaced) for every scene. Every arm has its own renderer (its own EGL context, as a
// single environment's), made on the worker thread that first draws the arm (an arm always runs
// on the same worker) and holding the arm's scene from its reset on, so every frame of an episode
// redraws only what changed (GlRendererOptions::incremental); one renderer per worker would
// re-upload a scene at every frame of a worker with several arms, which measured slower
// (BENCHMARKS.md). An arm's pixels are those of a renderer drawing that arm alone, the same as the
// single environment's image of the same state.
// The contexts stay bound to the threads that made them: part 0 runs on the caller's thread, so
// reset and step the batch from one thread once it renders. Needs the component manisoft::render
// (EGL, OpenGL); a renderer that cannot be made throws from the reset that first draws, naming
// the cause.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "manisoft/render/gl_renderer.hpp"
#include "manisoft/render/renderer.hpp"
#include "manisoft/scene/scene_render.hpp"
#include "manisoft/task/batched_task_env.hpp"

namespace manisoft::task {

template <render::Renderer R = render::GlRenderer>
class BasicBatchedTaskImages {
 public:
  /// Attaches to `batch` (its arm observer) before its first reset; `batch` must outlive this.
  BasicBatchedTaskImages(BatchedTaskEnv& batch, int width, int height, std::optional<render::Camera> camera = std::nullopt)
      : batch_(&batch), width_(width), height_(height), camera_(camera) {
    if (width < 1 || height < 1 || width > 4096 || height > 4096)
      manisoft::detail::fail("BatchedTaskImages: ", width, " x ", height, " pixels is invalid: width and height must lie in [1, 4096]");
    if (camera_) {
      camera_->width = width;
      camera_->height = height;
      render::validate(*camera_);
    }
    images_.assign(std::size_t(batch.batch_size()) * frame_bytes(), 0);
    arms_.resize(std::size_t(batch.batch_size()));
    batch.set_observer([this](int part, std::size_t i, bool reset) { draw(part, i, reset); });
  }
  BasicBatchedTaskImages(const BasicBatchedTaskImages&) = delete;
  BasicBatchedTaskImages& operator=(const BasicBatchedTaskImages&) = delete;
  ~BasicBatchedTaskImages() {
    batch_->set_observer(nullptr);
    try {  // each renderer released on the thread its context is current on
      batch_->for_each_part([this](int part) {
        for (Arm& arm : arms_)
          if (arm.part == part) arm.renderer.reset();
      });
    } catch (...) {  // what a renderer's release throws: the rest are released below
    }
  }

  int width() const { return width_; }
  int height() const { return height_; }
  /// B x height x width x 3 colour bytes, arm i's image at i * height * width * 3.
  std::span<const std::uint8_t> images() const { return images_; }

 private:
  struct Arm {
    std::unique_ptr<R> renderer;  ///< made on the worker thread that first draws the arm
    int part = -1;                ///< that worker
    render::tabletop::TabletopScene scene;  ///< the arm's current scene, built at its reset
    render::RenderOutput out;
    std::vector<math::Pose<double>> objects;
  };

  std::size_t frame_bytes() const { return std::size_t(width_) * std::size_t(height_) * 3; }

  void draw(int part, std::size_t i, bool reset) {
    const TaskEnv& env = batch_->arm(int(i));
    Arm& arm = arms_[i];
    if (!arm.renderer) {
      arm.renderer = render::make_colour_renderer<R>();
      arm.part = part;
    }
    if (reset) {
      arm.scene = scene::make_render_scene(batch_->scene(int(i)), env.library());
      render::Camera camera = camera_ ? *camera_ : arm.scene.scene.cameras.front();
      camera.width = width_;
      camera.height = height_;
      arm.scene.scene.cameras = {camera};
      arm.renderer->set_scene(arm.scene.scene);
    }
    const auto& world = env.world();
    const math::Pose<double> gripper{world.rigid().orientation(world.gripper_body()).toRotationMatrix(), world.rigid().position(world.gripper_body())};
    arm.objects.clear();
    for (const auto& o : env.snapshot().objects) arm.objects.push_back(o.pose);
    const render::FrameState frame = scene::render_frame(arm.scene, world.rod().state().positions, gripper, world.gripper().finger_width(), arm.objects);
    arm.renderer->render_into(frame, arm.out);
    if (arm.out.rgb.size() != frame_bytes())
      manisoft::detail::fail("BatchedTaskImages: arm ", i, "'s frame holds ", arm.out.rgb.size(), " bytes, expected ", frame_bytes());
    std::copy(arm.out.rgb.begin(), arm.out.rgb.end(), images_.begin() + std::ptrdiff_t(i * frame_bytes()));
  }

  BatchedTaskEnv* batch_;
  int width_, height_;
  std::optional<render::Camera> camera_;
  std::vector<std::uint8_t> images_;
  std::vector<Arm> arms_;
};

/// The images drawn with the in-process OpenGL renderer (OpenGL through EGL).
using BatchedTaskImages = BasicBatchedTaskImages<render::GlRenderer>;

}  // namespace manisoft::task
