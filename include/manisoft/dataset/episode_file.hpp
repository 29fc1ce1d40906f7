// Writing and reading one episode file of the expert dataset (HDF5, robomimic's layout):
//
//   /data/demo_<k>                 attributes: num_samples (robomimic), every Episode::text entry
//                                  (task, setting, scene JSON, instructions JSON, ...), every
//                                  Episode::numbers entry (success, seed, ...) and digest, the
//                                  content digest of all of it (episode_digest.hpp)
//   /data/demo_<k>/actions         float64 T x (3 n + 1): element torques row by row, then S
//                                  (actions and states: byte shuffle + gzip, chunks of 256
//                                  steps; about 3/4 of the raw size)
//   /data/demo_<k>/states          float64 T x D: the state before each action (replay)
//   /data/demo_<k>/rewards         float64 T
//   /data/demo_<k>/dones           uint8 T
//   /data/demo_<k>/obs/<name>      float32 T x k (uncompressed), and images taken at every
//                                  step as uint8 T x H x W x 3 (one gzip-compressed chunk a
//                                  frame: h5py reads them without any decoder)
//   /data/demo_<k>/images/<name>   image sequences taken every K steps: uint8 F x H x W x 3, with
//   /data/demo_<k>/images/<name>_steps  int64 F, the control step of each frame
//
// Writing is atomic: the file is written under a temporary name in the same folder, flushed,
// closed and then renamed, so a file with the final name is always complete; an interrupted write
// leaves only a "*.partial" file, which readers never open and generation redoes.
#pragma once

#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "manisoft/dataset/episode.hpp"
#include "manisoft/dataset/episode_digest.hpp"
#include "manisoft/dataset/hdf5.hpp"

namespace manisoft::dataset {

/// The group of episode k inside its file ("/data/demo_k").
inline std::string demo_path(long index) { return "/data/demo_" + std::to_string(index); }

/// The suffix of a file being written.
inline constexpr const char* partial_suffix = ".partial";

/// Writes `episode` to `path` atomically (see the header comment); `image_compression` is gzip's
/// level 0-9 for image arrays. Throws InvalidInput naming the field for an inconsistent episode
/// (nothing is written) and naming the file for an I/O failure (no file under `path` appears).
inline void write_episode(const std::filesystem::path& path, const Episode& episode, int image_compression = 4) {
  validate(episode);
  if (image_compression < 0 || image_compression > 9)
    ::manisoft::detail::fail("image_compression = ", image_compression, " must be within 0..9 (gzip levels)");
  const std::filesystem::path partial = path.string() + partial_suffix;
  try {
    h5::File file = h5::File::create(partial.string());
    const std::string demo = demo_path(episode.index);
    file.create_groups(demo + "/obs");
    const auto t = static_cast<hsize_t>(episode.steps());
    constexpr int array_level = 4;
    constexpr hsize_t array_rows = 256;
    auto write_array = [&](const std::string& name, const auto& m) {
      file.write(demo + name, {t, static_cast<hsize_t>(m.cols())}, m.data(), array_level, array_rows, true);
    };
    write_array("/actions", episode.actions);
    write_array("/states", episode.states);
    file.write(demo + "/rewards", {t}, episode.rewards.data());
    file.write(demo + "/dones", {t}, episode.dones.data());
    // Observations as float32 (what a policy trains on; the float64 states replay exactly),
    // uncompressed: smaller than shuffled + gzipped float64 and free to write and read.
    std::vector<float> narrowed;
    for (const auto& [name, m] : episode.observations) {
      narrowed.assign(m.data(), m.data() + m.size());
      file.write(demo + "/obs/" + name, {t, static_cast<hsize_t>(m.cols())}, narrowed.data());
    }
    for (const auto& [name, seq] : episode.images) {
      const std::vector<hsize_t> shape{static_cast<hsize_t>(seq.frames), static_cast<hsize_t>(seq.height),
                                       static_cast<hsize_t>(seq.width), 3};
      bool every_step = seq.frames == episode.steps();
      for (std::size_t f = 0; every_step && f < seq.steps.size(); ++f) every_step = seq.steps[f] == static_cast<long>(f);
      if (every_step) {
        file.write(demo + "/obs/" + name, shape, seq.pixels.data(), image_compression);
      } else {
        file.create_groups(demo + "/images");
        file.write(demo + "/images/" + name, shape, seq.pixels.data(), image_compression);
        file.write(demo + "/images/" + name + "_steps", {static_cast<hsize_t>(seq.frames)}, seq.steps.data());
      }
    }
    file.write_attribute(demo, "num_samples", static_cast<std::int64_t>(t));
    for (const auto& [name, value] : episode.text)
      if (name != digest_attribute) file.write_attribute(demo, name, value);
    for (const auto& [name, value] : episode.numbers)
      if (name != digest_attribute) file.write_attribute(demo, name, value);
    file.write_attribute(demo, digest_attribute, episode_digest(episode));
    file.close();
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(partial, ignored);
    throw;
  }
  std::error_code error;
  std::filesystem::rename(partial, path, error);
  if (error) {
    std::filesystem::remove(partial, error);
    ::manisoft::detail::fail(path.string(), ": cannot move the finished episode into place: ", error.message());
  }
}

/// Reads episode `index` back from `path`, checking what `validate` checks (names the file and
/// the field of the first problem).
inline Episode read_episode(const std::filesystem::path& path, long index) {
  const h5::File file = h5::File::open(path.string());
  const std::string demo = demo_path(index);
  if (!file.exists(demo)) h5::fail_at(file.name(), demo, "missing episode group");
  Episode e;
  e.index = index;
  const auto matrix = [&](const std::string& field) {
    std::vector<hsize_t> shape;
    const std::vector<double> values = file.read<double>(demo + "/" + field, shape);
    if (shape.size() != 2) h5::fail_at(file.name(), demo + "/" + field, "expected 2 dimensions, found ", shape.size());
    return StepMatrix(Eigen::Map<const StepMatrix>(values.data(), static_cast<Eigen::Index>(shape[0]),
                                                   static_cast<Eigen::Index>(shape[1])));
  };
  e.actions = matrix("actions");
  e.states = matrix("states");
  std::vector<hsize_t> shape;
  const std::vector<double> rewards = file.read<double>(demo + "/rewards", shape);
  e.rewards = Eigen::Map<const Eigen::VectorXd>(rewards.data(), static_cast<Eigen::Index>(rewards.size()));
  e.dones = file.read<std::uint8_t>(demo + "/dones", shape);
  const auto read_images = [&](const std::string& at, const std::string& name, std::vector<std::int64_t> steps) {
    ImageSequence seq;
    std::vector<hsize_t> s;
    seq.pixels = file.read<std::uint8_t>(at, s);
    if (s.size() != 4 || s[3] != 3) h5::fail_at(file.name(), at, "expected F x H x W x 3 pixels");
    seq.frames = static_cast<int>(s[0]);
    seq.height = static_cast<int>(s[1]);
    seq.width = static_cast<int>(s[2]);
    seq.steps = std::move(steps);
    e.images[name] = std::move(seq);
  };
  for (const std::string& name : file.children(demo + "/obs")) {
    const std::string at = demo + "/obs/" + name;
    const std::vector<hsize_t> s = file.shape(at);  // images are 4-D uint8, the rest 2-D float32
    if (s.size() == 4) {
      std::vector<std::int64_t> steps(s[0]);
      for (std::size_t f = 0; f < steps.size(); ++f) steps[f] = static_cast<std::int64_t>(f);
      read_images(at, name, std::move(steps));
    } else {
      e.observations[name] = matrix("obs/" + name);
    }
  }
  if (file.exists(demo + "/images")) {
    for (const std::string& name : file.children(demo + "/images")) {
      if (name.size() > 6 && name.ends_with("_steps")) continue;
      std::vector<hsize_t> s;
      read_images(demo + "/images/" + name, name, file.read<std::int64_t>(demo + "/images/" + name + "_steps", s));
    }
  }
  for (const std::string& name : file.attribute_names(demo)) {
    if (name == "num_samples") continue;
    if (name == digest_attribute) e.digest = file.read_string_attribute(demo, name);
    else if (file.attribute_is_string(demo, name)) e.text[name] = file.read_string_attribute(demo, name);
    else e.numbers[name] = file.read_numeric_attribute<double>(demo, name);
  }
  const auto samples = file.read_numeric_attribute<std::int64_t>(demo, "num_samples");
  if (samples != e.steps()) h5::fail_at(file.name(), demo, "num_samples = ", samples, " but actions has ", e.steps(), " rows");
  try {
    validate(e);
  } catch (const InvalidInput& error) {
    h5::fail_at(file.name(), demo, error.what());
  }
  return e;
}

}  // namespace manisoft::dataset
