// An OpenGL 3.3+ core context through EGL without a window or display server: Mesa's
// surfaceless platform (llvmpipe on a CPU machine) by default, or an EGL device by index
// (EGL_EXT_device_enumeration: a GPU's EGL driver). Rendering goes into framebuffer objects, so
// no EGL surface is created. Needs the component manisoft::render (EGL, OpenGL).
#pragma once

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <string>
#include <vector>

#include "manisoft/core/error.hpp"

namespace manisoft::render {

/// Which EGL display to open.
struct EglOptions {
  /// -1: Mesa's surfaceless platform with the default display (works with llvmpipe and with
  /// NVIDIA's EGL). >= 0: the EGL device of that index (EGL_EXT_device_enumeration).
  int device_index = -1;
};

namespace detail_egl {

inline const char* error_name(EGLint code) {
  switch (code) {
    case EGL_SUCCESS: return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    default: return "EGL error";
  }
}

}  // namespace detail_egl

/// Owns an EGL display reference and an OpenGL core context current on the creating thread.
class EglContext {
 public:
  explicit EglContext(const EglOptions& options = {}) {
    auto get_platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (get_platform_display == nullptr) {
      manisoft::detail::fail("EGL: eglGetPlatformDisplayEXT is not available (install an EGL vendor: libegl-mesa0 or the GPU driver's EGL)");
    }
    if (options.device_index < -1) {
      manisoft::detail::fail("EGL device_index = ", options.device_index, " is invalid: -1 (surfaceless platform) or a device index >= 0");
    }
    if (options.device_index < 0) {
      display_ = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
      if (display_ == EGL_NO_DISPLAY) {
        manisoft::detail::fail("EGL: no display on the surfaceless platform (EGL_PLATFORM_SURFACELESS_MESA): ",
                               detail_egl::error_name(eglGetError()), "; install libegl-mesa0 and libgl1-mesa-dri");
      }
    } else {
      auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
      if (query_devices == nullptr) manisoft::detail::fail("EGL: eglQueryDevicesEXT is not available: cannot open device_index = ", options.device_index);
      EGLint count = 0;
      if (!query_devices(0, nullptr, &count)) manisoft::detail::fail("EGL: eglQueryDevicesEXT failed: ", detail_egl::error_name(eglGetError()));
      if (options.device_index >= count) {
        manisoft::detail::fail("EGL device_index = ", options.device_index, " is out of range: EGL reports ", count, " device(s), valid indices 0..",
                               count - 1);
      }
      std::vector<EGLDeviceEXT> devices(static_cast<std::size_t>(count));
      query_devices(count, devices.data(), &count);
      display_ = get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[static_cast<std::size_t>(options.device_index)], nullptr);
      if (display_ == EGL_NO_DISPLAY) {
        manisoft::detail::fail("EGL: no display for device_index = ", options.device_index, ": ", detail_egl::error_name(eglGetError()));
      }
    }
    EGLint major = 0, minor = 0;
    if (!eglInitialize(display_, &major, &minor)) {
      manisoft::detail::fail("EGL: eglInitialize failed: ", detail_egl::error_name(eglGetError()));
    }
    try {
      if (!eglBindAPI(EGL_OPENGL_API)) manisoft::detail::fail("EGL: eglBindAPI(EGL_OPENGL_API) failed: ", detail_egl::error_name(eglGetError()));
      const EGLint config_attributes[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
      EGLConfig config = nullptr;
      EGLint configs = 0;
      if (!eglChooseConfig(display_, config_attributes, &config, 1, &configs) || configs < 1) config = nullptr;  // EGL_NO_CONFIG_KHR
      const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3, EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                           EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
      context_ = eglCreateContext(display_, config, EGL_NO_CONTEXT, context_attributes);
      if (context_ == EGL_NO_CONTEXT) {
        manisoft::detail::fail("EGL: cannot create an OpenGL 3.3 core context: ", detail_egl::error_name(eglGetError()));
      }
      make_current();
    } catch (...) {
      release();
      throw;
    }
  }

  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;
  ~EglContext() { release(); }

  /// Makes the context current on the calling thread (cheap when it already is).
  void make_current() const {
    if (eglGetCurrentContext() == context_) return;
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
      manisoft::detail::fail("EGL: eglMakeCurrent failed: ", detail_egl::error_name(eglGetError()));
    }
  }

  /// Makes the context current on the calling thread; false (nothing changed) when EGL refuses,
  /// e.g. while the context is current on another thread.
  bool try_make_current() const noexcept {
    return eglGetCurrentContext() == context_ || eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_) == EGL_TRUE;
  }

  EGLDisplay display() const { return display_; }

 private:
  void release() {
    if (display_ == EGL_NO_DISPLAY) return;
    if (context_ != EGL_NO_CONTEXT) {
      if (eglGetCurrentContext() == context_) eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      eglDestroyContext(display_, context_);
      context_ = EGL_NO_CONTEXT;
    }
    // The display stays initialised for the process's lifetime (no eglTerminate): EGL displays
    // are process-wide singletons, a later renderer reuses it without re-loading the driver, and
    // the driver's allocations stay attributable to its library (LeakSanitizer suppressions).
    display_ = EGL_NO_DISPLAY;
  }

  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
};

}  // namespace manisoft::render
