// MLP executor: a multilayer-perceptron policy read from a plain-text file,
// mapping a flat feature vector of the observation to element torques.
//
// Weight file format (text; '#' starts a comment to the end of the line; blank lines ignored;
// numbers separated by spaces or tabs):
//   manisoft-mlp 1              header and format version
//   layers L                    number of dense layers, L >= 1
//   input N0                    input size
//   then for each layer l = 1..L:
//     layer N_l ACT             output size and activation: linear | relu | tanh | sigmoid
//     N_l lines of N_{l-1} numbers: the weight matrix W_l, row-major (row i -> output i)
//     1 line of N_l numbers: the bias b_l
// Evaluation: h_0 = input, h_l = ACT_l(W_l h_{l-1} + b_l), output = h_L.
// Malformed files throw manisoft::Error naming the file and line.
//
// Executor features (input, size 24 + 6 m for m observed nodes), in this order:
//   target translation (3), target rotation column-major (9), end-effector translation (3),
//   end-effector rotation column-major (9), observed node positions (m x 3, node by node),
//   observed node velocities (m x 3, node by node).
// Output: the action, rows x 3 (row-major: row r's d1, d2, d3; rows = the action space's rows:
// n element torques in N m, or K B-spline control values), passed on unclamped: the
// arm world's control step applies the actuation limits. A non-finite output is refused naming
// its index (a policy that emits NaN is an error, not a zero torque). act() does not allocate.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "manisoft/control/executor.hpp"
#include "manisoft/core/error.hpp"

namespace manisoft::control {

enum class Activation { linear, relu, tanh, sigmoid };

template <typename Scalar>
class Mlp {
 public:
  using Matrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  using Vector = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
  struct Layer {
    Matrix weights;  ///< N_l x N_{l-1}
    Vector bias;     ///< N_l
    Activation activation = Activation::linear;
  };

  Mlp() = default;
  explicit Mlp(std::vector<Layer> layers) : layers_(std::move(layers)) {
    if (layers_.empty()) manisoft::detail::fail("Mlp needs at least one layer");
    for (std::size_t l = 0; l < layers_.size(); ++l) {
      if (layers_[l].bias.size() != layers_[l].weights.rows())
        manisoft::detail::fail("Mlp layer ", l + 1, ": bias has ", layers_[l].bias.size(), " entries, weights have ", layers_[l].weights.rows(), " rows");
      if (l > 0 && layers_[l].weights.cols() != layers_[l - 1].weights.rows())
        manisoft::detail::fail("Mlp layer ", l + 1, ": expects ", layers_[l].weights.cols(), " inputs, layer ", l, " gives ", layers_[l - 1].weights.rows());
    }
    buffers_.resize(layers_.size());
    for (std::size_t l = 0; l < layers_.size(); ++l) buffers_[l].setZero(layers_[l].weights.rows());
  }

  int input_size() const { return static_cast<int>(layers_.front().weights.cols()); }
  int output_size() const { return static_cast<int>(layers_.back().weights.rows()); }
  const std::vector<Layer>& layers() const { return layers_; }

  /// Evaluates the network; the returned reference is valid until the next call. No allocation.
  const Vector& evaluate(const Vector& input) {
    if (input.size() != input_size()) manisoft::detail::fail("Mlp expects ", input_size(), " inputs, got ", input.size());
    const Vector* h = &input;
    for (std::size_t l = 0; l < layers_.size(); ++l) {
      Vector& out = buffers_[l];
      out.noalias() = layers_[l].weights * *h;
      out += layers_[l].bias;
      switch (layers_[l].activation) {
        case Activation::linear: break;
        case Activation::relu: out = out.cwiseMax(Scalar(0)); break;
        case Activation::tanh: out = out.array().tanh().matrix(); break;
        case Activation::sigmoid: out = (Scalar(1) / (Scalar(1) + (-out.array()).exp())).matrix(); break;
      }
      h = &out;
    }
    return buffers_.back();
  }

  /// Reads the text format described at the top of this header.
  static Mlp load(const std::string& path) {
    std::ifstream in(path);
    if (!in) manisoft::detail::fail(path, ": cannot open the MLP weight file");
    Reader reader{in, path};
    std::vector<std::string> t = reader.next("the header 'manisoft-mlp 1'");
    if (t.size() != 2 || t[0] != "manisoft-mlp") reader.fail("expected the header 'manisoft-mlp 1'");
    if (t[1] != "1") reader.fail("unsupported format version '", t[1], "' (this reader knows version 1)");
    t = reader.next("'layers L'");
    if (t.size() != 2 || t[0] != "layers") reader.fail("expected 'layers L'");
    const int count = reader.positive_int(t[1], "layer count");
    t = reader.next("'input N'");
    if (t.size() != 2 || t[0] != "input") reader.fail("expected 'input N'");
    int previous = reader.positive_int(t[1], "input size");
    std::vector<Layer> layers;
    for (int l = 0; l < count; ++l) {
      t = reader.next("'layer N ACTIVATION'");
      if (t.size() != 3 || t[0] != "layer") reader.fail("expected 'layer N ACTIVATION' for layer ", l + 1);
      const int size = reader.positive_int(t[1], "layer size");
      Layer layer;
      layer.activation = reader.activation(t[2]);
      // Storage grows with the rows read, so sizes the file does not back are never allocated
      // ("input 1000000" and "layer 1000000" would be 8 TB).
      std::vector<Scalar> weights;
      for (int i = 0; i < size; ++i) {
        t = reader.next("a weight row");
        if (static_cast<int>(t.size()) != previous)
          reader.fail("layer ", l + 1, " weight row ", i + 1, " has ", t.size(), " numbers, expected ", previous);
        for (int j = 0; j < previous; ++j) weights.push_back(reader.number(t[j]));
      }
      layer.weights = Eigen::Map<const Matrix>(weights.data(), size, previous);
      t = reader.next("a bias row");
      if (static_cast<int>(t.size()) != size) reader.fail("layer ", l + 1, " bias has ", t.size(), " numbers, expected ", size);
      layer.bias.resize(size);
      for (int i = 0; i < size; ++i) layer.bias[i] = reader.number(t[i]);
      layers.push_back(std::move(layer));
      previous = size;
    }
    std::string rest;
    if (reader.try_next(rest)) reader.fail("unexpected content after the last layer: '", rest, "'");
    return Mlp(std::move(layers));
  }

 private:
  struct Reader {
    std::istream& in;
    std::string path;
    int line = 0;
    template <typename... Parts>
    [[noreturn]] void fail(Parts&&... parts) const {
      manisoft::detail::fail(path, ":", line, ": ", std::forward<Parts>(parts)...);
    }
    bool try_next(std::string& content) {
      std::string text;
      while (std::getline(in, text)) {
        ++line;
        const auto hash = text.find('#');
        if (hash != std::string::npos) text.erase(hash);
        if (text.find_first_not_of(" \t\r") == std::string::npos) continue;
        content = text;
        return true;
      }
      return false;
    }
    std::vector<std::string> next(const char* what) {
      std::string content;
      if (!try_next(content)) {
        ++line;
        fail("unexpected end of file, expected ", what);
      }
      std::istringstream words(content);
      std::vector<std::string> tokens;
      for (std::string w; words >> w;) tokens.push_back(w);
      return tokens;
    }
    Scalar number(const std::string& s) const {
      char* end = nullptr;
      const double v = std::strtod(s.c_str(), &end);
      if (s.empty() || end != s.c_str() + s.size()) fail("'", s, "' is not a number");
      if (!std::isfinite(v)) fail("'", s, "' is not finite");
      return static_cast<Scalar>(v);
    }
    int positive_int(const std::string& s, const char* what) const {
      char* end = nullptr;
      const long v = std::strtol(s.c_str(), &end, 10);
      if (s.empty() || end != s.c_str() + s.size() || v < 1 || v > 1000000) fail(what, " '", s, "' must be an integer in [1, 1000000]");
      return static_cast<int>(v);
    }
    Activation activation(const std::string& s) const {
      if (s == "linear") return Activation::linear;
      if (s == "relu") return Activation::relu;
      if (s == "tanh") return Activation::tanh;
      if (s == "sigmoid") return Activation::sigmoid;
      fail("unknown activation '", s, "' (expected linear, relu, tanh or sigmoid)");
    }
  };

  std::vector<Layer> layers_;
  std::vector<Vector> buffers_;
};

template <typename ScalarType>
class MlpExecutor {
 public:
  using Scalar = ScalarType;
  using Array3 = Eigen::Matrix<Scalar, Eigen::Dynamic, 3>;

  /// A policy whose network outputs `action_rows` x 3 values (element-major). `source` names the
  /// network in messages (its file).
  MlpExecutor(Mlp<Scalar> network, int action_rows, std::string_view source = "MlpExecutor") : network_(std::move(network)), rows_(action_rows) {
    if (action_rows < 1) manisoft::detail::fail(source, ": action_rows = ", action_rows, " must be >= 1");
    if (network_.output_size() != 3 * action_rows)
      manisoft::detail::fail(source, ": the network outputs ", network_.output_size(), " values, the action needs 3 x ", action_rows, " = ", 3 * action_rows);
    features_.setZero(network_.input_size());
  }

  /// The policy of weight file `path` (Mlp::load), refused naming the file when it does not fit.
  static MlpExecutor load(const std::string& path, int action_rows) { return MlpExecutor(Mlp<Scalar>::load(path), action_rows, path); }

  void reset() {}

  /// Number of features for m observed nodes.
  static int feature_size(int observed_nodes) { return 24 + 6 * observed_nodes; }

  void act(const Observation<Scalar>& o, Array3& action) {
    validate_observation(o, std::numeric_limits<int>::max());  // the network does not know the rod's node count
    const int m = static_cast<int>(o.node_indices.size());
    if (feature_size(m) != network_.input_size())
      manisoft::detail::fail("MlpExecutor: the observation gives ", feature_size(m), " features (", m, " nodes), the network expects ", network_.input_size());
    if (action.rows() != rows_) action.resize(rows_, 3);
    int f = 0;
    for (int i = 0; i < 3; ++i) features_[f++] = o.target.translation[i];
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) features_[f++] = o.target.rotation(r, c);
    for (int i = 0; i < 3; ++i) features_[f++] = o.end_effector.translation[i];
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) features_[f++] = o.end_effector.rotation(r, c);
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < 3; ++i) features_[f++] = o.node_positions(j, i);
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < 3; ++i) features_[f++] = o.node_velocities(j, i);
    const auto& out = network_.evaluate(features_);
    for (int k = 0; k < rows_; ++k)
      for (int i = 0; i < 3; ++i) {
        if (!std::isfinite(out[3 * k + i]))
          manisoft::detail::fail("MlpExecutor: network output ", 3 * k + i, " (action row ", k, ", column ", i, ") is not finite");
        action(k, i) = out[3 * k + i];
      }
  }

  const Mlp<Scalar>& network() const { return network_; }

 private:
  Mlp<Scalar> network_;
  int rows_;
  typename Mlp<Scalar>::Vector features_;
};

}  // namespace manisoft::control
