// The benchmark's flat action (paper section 3.2): the n x 3 element torques in the material
// frame (d1, d2, d3), flattened row by row (element 0 is the clamped base), then the gripper
// state S (>= 0.5 closed, below open). One definition for every place that packs or unpacks it:
// the Python environments, dataset files and their replay.
#pragma once

#include <string>

namespace manisoft::control {

struct FlatAction {
  /// Entries of the flat action of an arm of `elements` elements: 3n + 1.
  static constexpr int size(int elements) { return 3 * elements + 1; }
  /// Index of element `element`'s torque component `component` (0: d1, 1: d2, 2: d3).
  static constexpr int torque(int element, int component) { return 3 * element + component; }
  /// Index of S.
  static constexpr int gripper(int elements) { return 3 * elements; }
  /// S of a flat action's gripper entry: 1 (closed) from 0.5 up, else 0.
  static int gripper_state(double value) { return value >= 0.5 ? 1 : 0; }

  /// Writes torques (n x 3) and S into out[0 .. 3n] (any indexable: a row of an Eigen matrix, a
  /// numpy view).
  template <typename Torques, typename Out>
  static void pack(const Torques& torques, int s, Out&& out) {
    const int n = static_cast<int>(torques.rows());
    for (int k = 0; k < n; ++k)
      for (int c = 0; c < 3; ++c) out(torque(k, c)) = torques(k, c);
    out(gripper(n)) = s;
  }
  /// Reads torques (sized n x 3 already) from in[0 .. 3n - 1] and returns S.
  template <typename In, typename Torques>
  static int unpack(const In& in, Torques& torques) {
    const int n = static_cast<int>(torques.rows());
    for (int k = 0; k < n; ++k)
      for (int c = 0; c < 3; ++c) torques(k, c) = in(torque(k, c));
    return gripper_state(in(gripper(n)));
  }
  /// What entry `index` is, for error messages: "element 4, component d2" or "S".
  static std::string describe(int index, int elements) {
    if (index == gripper(elements)) return "S";
    return "element " + std::to_string(index / 3) + ", component d" + std::to_string(index % 3 + 1);
  }
};

}  // namespace manisoft::control
