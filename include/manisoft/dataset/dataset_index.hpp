// The dataset folder and its index file (the ManiSoft benchmark paper, section 3.5: 4:1 split of
// the scene-trajectory pairs), readable as ONE robomimic-style HDF5 file:
//
//   DIR/episodes/demo_<k>.hdf5   one complete episode each (episode_file.hpp), written by any
//                                number of generator processes (shards) in any order
//   DIR/dataset.hdf5             the index, written once every episode is there:
//     /data                      attributes total (sum of num_samples) and env_args (JSON);
//     /data/demo_<k>             HDF5 external links into the episode files (h5py and robomimic's
//                                readers follow them: f["data/demo_3/actions"] just works)
//     /mask/train, /mask/valid   fixed-length byte strings "demo_<k>" (robomimic's filter keys),
//                                4:1 per (task, setting) stratum: within a stratum, in index order,
//                                every fifth episode is validation
//
// `verify_dataset` opens every file, reads every episode through the index and checks shapes,
// finiteness, each episode's content digest (episode_digest.hpp), that an episode's recorded
// generate_args equal the index's env_args, the counts and that the masks cover every demo exactly
// once; it names the first bad file and field. (What an expert episode must hold beyond this is
// checked by expert_schema.hpp.)
#pragma once

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "manisoft/dataset/episode_file.hpp"

namespace manisoft::dataset {

inline std::filesystem::path episode_folder(const std::filesystem::path& dir) { return dir / "episodes"; }
inline std::filesystem::path episode_file(const std::filesystem::path& dir, long index) {
  return episode_folder(dir) / ("demo_" + std::to_string(index) + ".hdf5");
}
inline std::filesystem::path index_file(const std::filesystem::path& dir) { return dir / "dataset.hdf5"; }
/// The episode attribute holding the generator's arguments: the same JSON as the index's env_args.
inline constexpr const char* generate_args_attribute = "generate_args";

/// The complete episode files in DIR/episodes (partial files skipped), by index.
inline std::vector<long> complete_episodes(const std::filesystem::path& dir) {
  std::vector<long> indices;
  if (!std::filesystem::is_directory(episode_folder(dir))) return indices;
  for (const auto& entry : std::filesystem::directory_iterator(episode_folder(dir))) {
    const std::string name = entry.path().filename().string();
    if (!name.starts_with("demo_") || !name.ends_with(".hdf5")) continue;
    const std::string number = name.substr(5, name.size() - 10);
    if (number.empty() || number.find_first_not_of("0123456789") != std::string::npos) continue;
    indices.push_back(std::stol(number));
  }
  std::sort(indices.begin(), indices.end());
  return indices;
}

/// The 4:1 train / valid split of `indices` stratified by `stratum_of(index)`.
template <typename StratumOf>
std::pair<std::vector<long>, std::vector<long>> split_four_to_one(const std::vector<long>& indices, StratumOf stratum_of) {
  std::map<std::string, std::vector<long>> strata;
  for (long k : indices) strata[stratum_of(k)].push_back(k);
  std::vector<long> train, valid;
  for (auto& [name, members] : strata) {
    std::sort(members.begin(), members.end());
    for (std::size_t i = 0; i < members.size(); ++i) (i % 5 == 4 ? valid : train).push_back(members[i]);
  }
  std::sort(train.begin(), train.end());
  std::sort(valid.begin(), valid.end());
  return {train, valid};
}

/// Writes DIR/dataset.hdf5 over the complete episodes, atomically. `env_args` is the JSON that
/// rebuilds the environment (robomimic's data attribute). `expected`: the number of episodes the
/// dataset must have (0: any); fewer complete files is an error naming the first missing index.
inline void write_index(const std::filesystem::path& dir, const std::string& env_args, long expected = 0) {
  const std::vector<long> indices = complete_episodes(dir);
  if (expected > 0) {
    for (long k = 0; k < expected; ++k)
      if (!std::binary_search(indices.begin(), indices.end(), k))
        ::manisoft::detail::fail(episode_file(dir, k).string(), ": missing (", indices.size(), " of ", expected,
                                 " episodes complete): generate it before indexing");
  }
  std::map<long, std::string> stratum;
  long total = 0;
  for (long k : indices) {
    const h5::File f = h5::File::open(episode_file(dir, k).string());
    const std::string demo = demo_path(k);
    total += f.read_numeric_attribute<std::int64_t>(demo, "num_samples");
    const auto text_or = [&](const char* name) {
      const auto names = f.attribute_names(demo);
      return std::find(names.begin(), names.end(), name) != names.end() ? f.read_string_attribute(demo, name) : "";
    };
    stratum[k] = text_or("task") + "/" + text_or("setting");
  }
  const auto [train, valid] = split_four_to_one(indices, [&](long k) { return stratum.at(k); });

  const std::filesystem::path final_path = index_file(dir);
  const std::filesystem::path partial = final_path.string() + partial_suffix;
  try {
    h5::File index = h5::File::create(partial.string());
    index.create_groups("/data");
    index.create_groups("/mask");
    for (long k : indices) {
      const std::string target = (std::filesystem::path("episodes") / episode_file(dir, k).filename()).string();
      index.link_external(demo_path(k), target, demo_path(k));
    }
    index.write_attribute("/data", "total", total);
    index.write_attribute("/data", "env_args", env_args);
    const auto names = [](const std::vector<long>& ks) {
      std::vector<std::string> out;
      for (long k : ks) out.push_back("demo_" + std::to_string(k));
      return out;
    };
    index.write_strings("/mask/train", names(train));
    index.write_strings("/mask/valid", names(valid));
    index.close();
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(partial, ignored);
    throw;
  }
  std::error_code error;
  std::filesystem::rename(partial, final_path, error);
  if (error) ::manisoft::detail::fail(final_path.string(), ": cannot move the index into place: ", error.message());
}

/// What verify_dataset found.
struct VerifyReport {
  long episodes = 0;
  long steps = 0;
  long train = 0, valid = 0;
  long partial_files = 0;  ///< "*.partial" left by an interrupted generator (not an error)
};

/// Refuses an episode read from `file` whose digest attribute is missing or differs from its content.
inline void check_digest(const std::filesystem::path& file, const Episode& e) {
  if (e.digest.empty())
    h5::fail_at(file.string(), demo_path(e.index), "missing attribute '", digest_attribute,
                "' (the content digest; files written before digests existed cannot be checked: regenerate them)");
  const std::string actual = episode_digest(e);
  if (actual != e.digest)
    h5::fail_at(file.string(), demo_path(e.index), "content digest mismatch: attribute ", digest_attribute, " = ", e.digest,
                ", the content gives ", actual, " (a dataset or attribute was changed after writing)");
}

/// Checks the whole dataset; throws InvalidInput naming the first bad file and field.
/// `check_episode(file, episode)` runs on each episode once it is read, before its digest is
/// checked (expert_schema.hpp's check_expert_episode: a broken rule is named as such).
template <typename CheckEpisode>
VerifyReport verify_dataset(const std::filesystem::path& dir, CheckEpisode&& check_episode) {
  VerifyReport report;
  const h5::File index = h5::File::open(index_file(dir).string());
  const std::vector<long> indices = complete_episodes(dir);
  const std::vector<std::string> linked = index.children("/data");
  std::set<std::string> demos(linked.begin(), linked.end());
  const std::string env_args = index.read_string_attribute("/data", "env_args");
  for (long k : indices) {
    if (!demos.count("demo_" + std::to_string(k)))
      h5::fail_at(index.name(), "/data", "episode file ", episode_file(dir, k).string(), " is not in the index");
  }
  for (const std::string& demo : linked) {
    const std::string number = demo.substr(std::min<std::size_t>(5, demo.size()));
    if (!demo.starts_with("demo_") || number.empty() || number.size() > 12 || number.find_first_not_of("0123456789") != std::string::npos)
      h5::fail_at(index.name(), "/data/" + demo, "is not named demo_<k>");
    const long k = std::stol(number);
    const Episode e = read_episode(episode_file(dir, k), k);  // names the episode file and field
    check_episode(episode_file(dir, k), e);
    check_digest(episode_file(dir, k), e);
    const auto args = e.text.find(generate_args_attribute);
    if (args != e.text.end() && args->second != env_args)
      h5::fail_at(episode_file(dir, k).string(), demo_path(k), "attribute ", generate_args_attribute, " = ", args->second,
                  " differs from the index's env_args = ", env_args, " (episodes of another run)");
    ++report.episodes;
    report.steps += e.steps();
    std::vector<hsize_t> shape = index.shape(demo_path(k) + "/actions");  // the link resolves
    if (shape.empty() || static_cast<long>(shape[0]) != e.steps())
      h5::fail_at(index.name(), demo_path(k), "the link does not reach episode ", k);
  }
  const auto total = index.read_numeric_attribute<std::int64_t>("/data", "total");
  if (total != report.steps) h5::fail_at(index.name(), "/data", "total = ", total, " but the episodes have ", report.steps, " steps");
  std::set<std::string> seen;
  for (const char* split : {"train", "valid"}) {
    const auto members = index.read_strings(std::string("/mask/") + split);
    (std::string(split) == "train" ? report.train : report.valid) = static_cast<long>(members.size());
    for (const auto& m : members) {
      if (!demos.count(m)) h5::fail_at(index.name(), std::string("/mask/") + split, "names ", m, ", which is not in /data");
      if (!seen.insert(m).second) h5::fail_at(index.name(), std::string("/mask/") + split, m, " is in more than one split");
    }
  }
  if (seen.size() != demos.size())
    h5::fail_at(index.name(), "/mask", "the splits cover ", seen.size(), " of ", demos.size(), " demos");
  for (const auto& entry : std::filesystem::directory_iterator(episode_folder(dir)))
    if (entry.path().string().ends_with(partial_suffix)) ++report.partial_files;
  return report;
}

inline VerifyReport verify_dataset(const std::filesystem::path& dir) {
  return verify_dataset(dir, [](const std::filesystem::path&, const Episode&) {});
}

}  // namespace manisoft::dataset
