// Read-back of a rendered frame (gl_renderer.hpp): the multisampled targets resolved, then colour,
// object ids and depth read with glReadPixels into a RenderOutput. Rows come back top row first
// because the renderer draws the image upside down (gl_projection.hpp, camera_view_projection).
// Colour is read as RGBA, llvmpipe's copy path for an RGBA8 target (GL_RGB goes through Mesa's
// format conversion, about 8x slower), and the alpha dropped here; depth is read as the 24-bit
// depth buffer and linearised to metres along the camera's z axis (linear_depth).
#pragma once

#include <GL/glcorearb.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "manisoft/render/camera.hpp"
#include "manisoft/render/gl_resources.hpp"
#include "manisoft/render/image.hpp"

namespace manisoft::render::detail_gl {

/// Distances along the camera's z axis (m) of 24-bit depth-buffer values read as GL_UNSIGNED_INT
/// (the depth D in the top 24 bits), for a perspective projection with clip range [n, f]; 0 where
/// the buffer holds the far plane (background). Window depth d = D / M (M = 2^24 - 1) -> NDC
/// z = 2 d - 1 -> eye distance 2 n f / ((f + n) - z (f - n)) = n f / (n + (1 - d) (f - n)); 1 - d
/// from integers (no cancellation), in float (vectorised).
inline void linear_depth(const std::uint32_t* src, float* dst, std::size_t count, double near_clip, double far_clip) {
  const float n = static_cast<float>(near_clip), f = static_cast<float>(far_clip);
  const float nf = n * f, scale = static_cast<float>((far_clip - near_clip) / 16777215.0);
  for (std::size_t i = 0; i < count; ++i) {
    const auto far_steps = static_cast<std::int32_t>(0xFFFFFFu - (src[i] >> 8));  // M - D
    const float z = nf / (n + static_cast<float>(far_steps) * scale);
    dst[i] = far_steps == 0 ? 0.0f : z;
  }
}

/// Resolves the multisampled targets (colour with depth, then the ids when `mask`) into the
/// single-sampled ones; returns the framebuffer to read from.
inline GLuint resolve_msaa(const RenderTargets& targets, int width, int height, bool mask, bool depth) {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, targets.main_fbo);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, targets.resolve_fbo);
  for (int a = 0; a < (mask ? 2 : 1); ++a) {
    glReadBuffer(GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(a));
    const GLenum draw_buffers[2] = {a == 0 ? GLenum(GL_COLOR_ATTACHMENT0) : GLenum(GL_NONE), a == 1 ? GLenum(GL_COLOR_ATTACHMENT1) : GLenum(GL_NONE)};
    glDrawBuffers(2, draw_buffers);
    glBlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL_COLOR_BUFFER_BIT | (a == 0 && depth ? GL_DEPTH_BUFFER_BIT : 0), GL_NEAREST);
  }
  return targets.resolve_fbo;
}

/// Reads frames back into RenderOutputs, keeping its scratch buffers between frames (no
/// allocation once they have the right size).
class ReadBack {
 public:
  /// Fills `out` (size, camera, rgb; mask and depth when asked, else empties them) from
  /// framebuffer `fbo` (colour attachment 0, ids attachment 1, depth).
  void read(GLuint fbo, const Camera& camera, const CameraModel& model, bool mask, bool depth, RenderOutput& out) {
    const int w = camera.width, h = camera.height;
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    const std::size_t pixels = static_cast<std::size_t>(w) * h;
    out.width = w;
    out.height = h;
    out.camera = model;
    read_rgb(w, h, out.rgb);
    if (mask) {
      out.mask.resize(pixels);
      glReadBuffer(GL_COLOR_ATTACHMENT1);
      glReadPixels(0, 0, w, h, GL_RED_INTEGER, GL_UNSIGNED_SHORT, out.mask.data());
    } else {
      out.mask.clear();
    }
    if (depth) {
      scratch_depth_.resize(pixels);
      out.depth.resize(pixels);
      glReadPixels(0, 0, w, h, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, scratch_depth_.data());
      linear_depth(scratch_depth_.data(), out.depth.data(), pixels, camera.near_clip, camera.far_clip);
    } else {
      out.depth.clear();
    }
  }

 private:
  // Colour as RGBA (the copy path), alpha dropped.
  void read_rgb(int w, int h, std::vector<std::uint8_t>& out) {
    const std::size_t pixels = static_cast<std::size_t>(w) * h;
    out.resize(pixels * 3);
    scratch_rgba_.resize(pixels);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, scratch_rgba_.data());
    const std::array<std::uint8_t, 4>* rgba = scratch_rgba_.data();
    std::uint8_t* rgb = out.data();
    for (std::size_t i = 0; i < pixels; ++i) {
      rgb[3 * i] = rgba[i][0];
      rgb[3 * i + 1] = rgba[i][1];
      rgb[3 * i + 2] = rgba[i][2];
    }
  }

  std::vector<std::uint32_t> scratch_depth_;
  std::vector<std::array<std::uint8_t, 4>> scratch_rgba_;
};

}  // namespace manisoft::render::detail_gl
