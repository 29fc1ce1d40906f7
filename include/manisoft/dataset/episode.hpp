// One recorded episode of the expert dataset (the ManiSoft benchmark paper, section 3.5: scene-
// trajectory pairs), in the layout robot-learning code reads (robomimic's HDF5 convention, which
// Diffusion Policy reads; LIBERO uses the same): per control step the action (n x 3 element
// torques flattened row by row, then the gripper state S), the state needed to replay the episode
// exactly, reward and done; named observation arrays (end-effector pose, rod shape, object poses)
// and image sequences (uint8 T x H x W x 3); string and number attributes (task, setting, scene
// JSON, instructions, seeds, success). `validate` refuses an episode whose arrays disagree in
// length, whose numbers are not finite, or whose names could not be stored, naming the field.
#pragma once

#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "manisoft/core/error.hpp"

namespace manisoft::dataset {

/// Rows are control steps.
using StepMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// T frames of H x W RGB, row-major (frame, row, column, channel).
struct ImageSequence {
  int frames = 0, height = 0, width = 0;
  std::vector<std::uint8_t> pixels;  ///< frames * height * width * 3
  /// The control step each frame was taken at (images may be sparser than steps: every K steps).
  std::vector<std::int64_t> steps;
};

struct Episode {
  long index = 0;  ///< demo_<index>
  StepMatrix actions;   ///< T x (3 n + 1)
  StepMatrix states;    ///< T x D (the state before each action)
  Eigen::VectorXd rewards;               ///< T
  std::vector<std::uint8_t> dones;       ///< T, 1 at the last step
  std::map<std::string, StepMatrix> observations;   ///< name -> T x k
  std::map<std::string, ImageSequence> images;      ///< name -> frames
  std::map<std::string, std::string> text;          ///< task, setting, scene (JSON), instructions (JSON), ...
  std::map<std::string, double> numbers;            ///< success, seed, ...
  /// The digest attribute read from a file (episode_digest.hpp); "" when the file has none.
  /// write_episode ignores it and stores the digest of what it writes.
  std::string digest;

  long steps() const { return static_cast<long>(actions.rows()); }
};

namespace detail {

inline void require_name(const std::string& what, const std::string& name) {
  if (name.empty() || name.find('/') != std::string::npos || name.find('.') == 0) {
    ::manisoft::detail::fail("episode ", what, " name '", name, "' is invalid: non-empty, no '/', not starting with '.'");
  }
}

inline void require_finite(const std::string& field, const StepMatrix& m) {
  for (Eigen::Index r = 0; r < m.rows(); ++r)
    for (Eigen::Index c = 0; c < m.cols(); ++c)
      if (!std::isfinite(m(r, c))) ::manisoft::detail::fail(field, "[", r, ", ", c, "] = ", m(r, c), " is not finite");
}

}  // namespace detail

/// Refuses an inconsistent episode before anything is written (names the field and the entry).
inline void validate(const Episode& e) {
  const long t = e.steps();
  if (t < 1) ::manisoft::detail::fail("episode ", e.index, ": no steps (actions has 0 rows)");
  if (e.index < 0) ::manisoft::detail::fail("episode index ", e.index, " must be >= 0");
  const auto rows = [&](const std::string& field, Eigen::Index n) {
    if (n != t) ::manisoft::detail::fail("episode ", e.index, ": ", field, " has ", n, " rows, actions has ", t);
  };
  rows("states", e.states.rows());
  rows("rewards", e.rewards.size());
  rows("dones", static_cast<Eigen::Index>(e.dones.size()));
  detail::require_finite("actions", e.actions);
  detail::require_finite("states", e.states);
  detail::require_finite("rewards", StepMatrix(e.rewards.transpose()));
  for (const auto& [name, m] : e.observations) {
    detail::require_name("observation", name);
    rows("obs/" + name, m.rows());
    detail::require_finite("obs/" + name, m);
  }
  for (const auto& [name, seq] : e.images) {
    detail::require_name("image", name);
    if (seq.frames < 0 || seq.height < 1 || seq.width < 1 ||
        seq.pixels.size() != static_cast<std::size_t>(seq.frames) * seq.height * seq.width * 3 ||
        seq.steps.size() != static_cast<std::size_t>(seq.frames)) {
      ::manisoft::detail::fail("episode ", e.index, ": images/", name, " has ", seq.pixels.size(), " bytes and ",
                               seq.steps.size(), " step numbers for ", seq.frames, " frames of ", seq.height, " x ",
                               seq.width, " x 3");
    }
    for (std::int64_t s : seq.steps)
      if (s < 0 || s >= t) ::manisoft::detail::fail("episode ", e.index, ": images/", name, " frame at step ", s, " outside 0..", t - 1);
  }
  for (const auto& [name, value] : e.numbers) {
    detail::require_name("number", name);
    if (!std::isfinite(value)) ::manisoft::detail::fail("episode ", e.index, ": attribute ", name, " = ", value, " is not finite");
  }
  for (const auto& [name, value] : e.text) detail::require_name("text", name);
}

}  // namespace manisoft::dataset
