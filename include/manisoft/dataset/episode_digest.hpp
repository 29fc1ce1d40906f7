// The content digest of one episode file: 64-bit FNV-1a (Fowler, Noll, Vo) over the episode's
// datasets and attributes in a fixed order, stored as the string attribute `digest`
// ("fnv1a64:" and 16 lowercase hex digits) when the episode is written, and recomputed by
// verify_dataset. Any changed byte of any dataset or attribute changes it, including a value that
// is still in range. The byte stream, so that any reader can recompute it:
//   every dataset of the demo group, ordered by its path relative to the group ("actions",
//   "obs/eef_pose", "images/agentview_image_steps"; byte order of the paths): the path, a NUL
//   byte, the rank and each dimension as little-endian uint64, then the elements in row-major
//   order as little-endian bytes of the stored type (actions, states, rewards float64; dones and
//   images uint8; other obs float32; <name>_steps int64);
//   then every attribute except `digest`, ordered by name: the name, a NUL byte, then a string's
//   UTF-8 bytes and a NUL byte, or a number's 8 little-endian bytes (num_samples int64, the
//   others float64).
#pragma once

#include <bit>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "manisoft/dataset/episode.hpp"

namespace manisoft::dataset {

/// The name of the digest attribute.
inline constexpr const char* digest_attribute = "digest";

/// 64-bit FNV-1a over bytes fed in order.
class Fnv1a64 {
 public:
  void byte(std::uint8_t b) { state_ = (state_ ^ b) * 0x100000001b3ULL; }
  void text(const std::string& s) {
    for (char c : s) byte(static_cast<std::uint8_t>(c));
    byte(0);
  }
  void u64(std::uint64_t v) {
    for (int i = 0; i < 8; ++i) byte(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  void f64(double v) { u64(std::bit_cast<std::uint64_t>(v)); }
  void f32(float v) {
    const auto bits = std::bit_cast<std::uint32_t>(v);
    for (int i = 0; i < 4; ++i) byte(static_cast<std::uint8_t>(bits >> (8 * i)));
  }
  std::uint64_t value() const { return state_; }

 private:
  std::uint64_t state_ = 0xcbf29ce484222325ULL;
};

/// The digest of `e` as write_episode stores it (see the header comment).
inline std::string episode_digest(const Episode& e) {
  using Feed = std::function<void(Fnv1a64&)>;
  std::map<std::string, Feed> datasets, attributes;  // ordered by path / name
  const auto shape = [](Fnv1a64& h, std::vector<std::uint64_t> dims) {
    h.u64(dims.size());
    for (auto d : dims) h.u64(d);
  };
  const auto rows = static_cast<std::uint64_t>(e.steps());
  const auto matrix = [&](const StepMatrix& m, bool narrow) -> Feed {
    return [&m, narrow, shape](Fnv1a64& h) {
      shape(h, {static_cast<std::uint64_t>(m.rows()), static_cast<std::uint64_t>(m.cols())});
      for (Eigen::Index i = 0; i < m.size(); ++i) narrow ? h.f32(static_cast<float>(m.data()[i])) : h.f64(m.data()[i]);
    };
  };
  datasets["actions"] = matrix(e.actions, false);
  datasets["states"] = matrix(e.states, false);
  datasets["rewards"] = [&](Fnv1a64& h) {
    shape(h, {rows});
    for (Eigen::Index i = 0; i < e.rewards.size(); ++i) h.f64(e.rewards(i));
  };
  datasets["dones"] = [&](Fnv1a64& h) {
    shape(h, {rows});
    for (auto d : e.dones) h.byte(d);
  };
  for (const auto& [name, m] : e.observations) datasets["obs/" + name] = matrix(m, true);
  for (const auto& image : e.images) {  // (no structured bindings: lambdas below capture them)
    const std::string& name = image.first;
    const ImageSequence& seq = image.second;
    bool every_step = seq.frames == e.steps();  // stored under obs/ (as write_episode decides)
    for (std::size_t f = 0; every_step && f < seq.steps.size(); ++f) every_step = seq.steps[f] == static_cast<long>(f);
    const std::string at = (every_step ? "obs/" : "images/") + name;
    datasets[at] = [&seq, shape](Fnv1a64& h) {
      shape(h, {static_cast<std::uint64_t>(seq.frames), static_cast<std::uint64_t>(seq.height), static_cast<std::uint64_t>(seq.width), 3});
      for (auto p : seq.pixels) h.byte(p);
    };
    if (!every_step)
      datasets[at + "_steps"] = [&seq, shape](Fnv1a64& h) {
        shape(h, {seq.steps.size()});
        for (auto s : seq.steps) h.u64(static_cast<std::uint64_t>(s));
      };
  }
  attributes["num_samples"] = [&](Fnv1a64& h) { h.u64(rows); };
  for (const auto& text : e.text) attributes[text.first] = [&value = text.second](Fnv1a64& h) { h.text(value); };
  for (const auto& number : e.numbers) attributes[number.first] = [value = number.second](Fnv1a64& h) { h.f64(value); };
  attributes.erase(digest_attribute);
  Fnv1a64 h;
  for (const auto& [path, feed] : datasets) h.text(path), feed(h);
  for (const auto& [name, feed] : attributes) h.text(name), feed(h);
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h.value()));
  return std::string("fnv1a64:") + hex;
}

}  // namespace manisoft::dataset
