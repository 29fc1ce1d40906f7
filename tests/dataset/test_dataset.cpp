// The expert dataset's files (include/manisoft/dataset/): an episode written and read back is
// bit-identical; bad episodes are refused before anything reaches the disk; truncated or
// corrupted files are detected naming the file; the index links every episode, splits 4:1 per
// stratum (hand-computed) and verify_dataset checks it all; h5py reads the index with no code of
// ours (examples/python/read_dataset.py).
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>

#include "../support/command_line.hpp"
#include "../support/scratch_dir.hpp"
#include "manisoft/dataset/dataset_index.hpp"

namespace {

namespace ds = manisoft::dataset;
namespace fs = std::filesystem;

/// A synthetic episode with every kind of field; values from a seeded engine (raw draws).
ds::Episode make_episode(long index, long steps, const std::string& task, const std::string& setting) {
  std::mt19937_64 engine(static_cast<std::uint64_t>(index) * 7919u + 1u);
  const auto value = [&] { return static_cast<double>(engine() >> 11) * 0x1.0p-53 * 300.0 - 150.0; };
  ds::Episode e;
  e.index = index;
  e.actions.resize(steps, 61);
  e.states.resize(steps, 17);
  e.rewards.resize(steps);
  for (long t = 0; t < steps; ++t) {
    for (int c = 0; c < 61; ++c) e.actions(t, c) = value();
    for (int c = 0; c < 17; ++c) e.states(t, c) = value();
    e.rewards(t) = value();
    e.dones.push_back(t + 1 == steps ? 1 : 0);
  }
  ds::StepMatrix pose(steps, 7);
  for (long t = 0; t < steps; ++t)
    for (int c = 0; c < 7; ++c) pose(t, c) = value();
  e.observations["ee_pose"] = pose;
  ds::ImageSequence dense{static_cast<int>(steps), 4, 5, {}, {}};
  for (long t = 0; t < steps; ++t) dense.steps.push_back(t);
  for (int i = 0; i < dense.frames * 4 * 5 * 3; ++i) dense.pixels.push_back(static_cast<std::uint8_t>(engine()));
  e.images["agentview_image"] = dense;
  ds::ImageSequence sparse{2, 3, 2, {}, {0, steps - 1}};
  for (int i = 0; i < 2 * 3 * 2 * 3; ++i) sparse.pixels.push_back(static_cast<std::uint8_t>(engine()));
  e.images["every_k"] = sparse;
  e.text["task"] = task;
  e.text["setting"] = setting;
  e.text["scene"] = R"({"table": {"height": 0.75}, "note": "ünïcode ok"})";
  e.numbers["success"] = 1;
  e.numbers["seed"] = static_cast<double>(index) + 0.5;
  return e;
}

void check_read_back(const ds::Episode& a, const ds::Episode& b) {
  CHECK(a.index == b.index);
  CHECK(a.actions == b.actions);  // exact: bit for bit
  CHECK(a.states == b.states);
  CHECK(a.rewards == b.rewards);
  CHECK(a.dones == b.dones);
  REQUIRE(a.observations.size() == b.observations.size());
  // observations are stored as float32: read back, each value is the float nearest the written one
  for (const auto& [name, m] : a.observations) CHECK(b.observations.at(name) == m.cast<float>().cast<double>());
  REQUIRE(a.images.size() == b.images.size());
  for (const auto& [name, seq] : a.images) {
    const auto& other = b.images.at(name);
    CHECK(other.frames == seq.frames);
    CHECK(other.height == seq.height);
    CHECK(other.width == seq.width);
    CHECK(other.pixels == seq.pixels);
    CHECK(other.steps == seq.steps);
  }
  CHECK(a.text == b.text);
  CHECK(a.numbers == b.numbers);
}

}  // namespace

TEST_CASE("an episode written and read back is bit-identical (observations: to the nearest float32)", "[dataset]") {
  const fs::path dir = manisoft::test::scratch_dir("manisoft_dataset_roundtrip");
  const ds::Episode e = make_episode(3, 12, "COLL", "clean");
  ds::write_episode(dir / "demo_3.hdf5", e);
  CHECK_FALSE(fs::exists(dir / "demo_3.hdf5.partial"));
  check_read_back(e, ds::read_episode(dir / "demo_3.hdf5", 3));
  CHECK_THROWS_WITH(ds::read_episode(dir / "demo_3.hdf5", 4), Catch::Contains("/data/demo_4: missing episode group"));
}

TEST_CASE("a bad episode is refused naming the field, and nothing reaches the disk", "[dataset][input]") {
  const fs::path dir = manisoft::test::scratch_dir("manisoft_dataset_bad");
  ds::Episode e = make_episode(0, 6, "ALN", "randomized");
  e.actions(3, 2) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(ds::write_episode(dir / "demo_0.hdf5", e), Catch::Contains("actions[3, 2] = nan is not finite"));
  e = make_episode(0, 6, "ALN", "randomized");
  e.states.conservativeResize(5, Eigen::NoChange);
  CHECK_THROWS_WITH(ds::write_episode(dir / "demo_0.hdf5", e), Catch::Contains("states has 5 rows, actions has 6"));
  e = make_episode(0, 6, "ALN", "randomized");
  e.images["every_k"].steps[1] = 6;
  CHECK_THROWS_WITH(ds::write_episode(dir / "demo_0.hdf5", e), Catch::Contains("frame at step 6 outside 0..5"));
  e = make_episode(0, 6, "ALN", "randomized");
  e.observations["a/b"] = e.observations["ee_pose"];
  CHECK_THROWS_WITH(ds::write_episode(dir / "demo_0.hdf5", e), Catch::Contains("name 'a/b' is invalid"));
  CHECK(fs::is_empty(dir));
  // An unwritable place: the error names the file, and no file appears.
  CHECK_THROWS_WITH(ds::write_episode(dir / "no_such_folder" / "demo_0.hdf5", make_episode(0, 6, "ALN", "clean")),
                    Catch::Contains("no_such_folder/demo_0.hdf5.partial: cannot create"));
  CHECK(fs::is_empty(dir));
}

TEST_CASE("truncated and corrupted episode files are detected, naming the file", "[dataset][input]") {
  const fs::path dir = manisoft::test::scratch_dir("manisoft_dataset_damaged");
  const ds::Episode e = make_episode(1, 40, "STK", "clean");
  const fs::path good = dir / "demo_1.hdf5";
  ds::write_episode(good, e);
  const auto size = fs::file_size(good);
  for (const double keep : {0.5, 0.9, 0.99}) {
    const fs::path cut = dir / "cut.hdf5";
    fs::copy_file(good, cut, fs::copy_options::overwrite_existing);
    fs::resize_file(cut, static_cast<std::uintmax_t>(static_cast<double>(size) * keep));
    CAPTURE(keep);
    CHECK_THROWS_WITH(ds::read_episode(cut, 1), Catch::Contains("cut.hdf5"));
  }
  // Overwrite the superblock's signature: not an HDF5 file any more.
  const fs::path bad = dir / "bad.hdf5";
  fs::copy_file(good, bad, fs::copy_options::overwrite_existing);
  {
    std::fstream f(bad, std::ios::in | std::ios::out | std::ios::binary);
    f.write("garbage!", 8);
  }
  CHECK_THROWS_WITH(ds::read_episode(bad, 1), Catch::Contains("bad.hdf5: not a readable HDF5 file"));
}

TEST_CASE("a dataset declaring more values than its file stores is refused before they are allocated", "[dataset][input]") {
  // /data/demo_0/actions declared 2^40 x 7 (56 TB of float64) in chunks never written: a 3 KB file
  // (tests/fuzz/corpus/episode_file/huge_dims.hdf5 is the same file written by h5py)
  const fs::path path = manisoft::test::scratch_dir("manisoft_dataset_huge_dims") / "huge_dims.hdf5";
  {
    const ds::h5::Handle file(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose);
    const ds::h5::Handle links(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
    H5Pset_create_intermediate_group(links.get(), 1);
    const hsize_t dims[2] = {hsize_t{1} << 40, 7}, chunk[2] = {256, 7};
    const ds::h5::Handle space(H5Screate_simple(2, dims, nullptr), H5Sclose);
    const ds::h5::Handle layout(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
    H5Pset_chunk(layout.get(), 2, chunk);
    const ds::h5::Handle data(H5Dcreate2(file.get(), "/data/demo_0/actions", H5T_NATIVE_DOUBLE, space.get(), links.get(), layout.get(), H5P_DEFAULT),
                              H5Dclose);
    REQUIRE(data.valid());
  }
  CHECK_THROWS_WITH(ds::read_episode(path, 0),
                    Catch::Contains("huge_dims.hdf5: /data/demo_0/actions: a dataset of 1099511627776 x 7 values of 8 bytes has only 0 bytes stored"));
}

TEST_CASE("64-bit FNV-1a gives the published test vectors", "[dataset]") {
  // Fowler, Noll, Vo: FNV-1a 64 of "", "a" and "foobar" (the reference test suite).
  const auto fnv = [](const std::string& s) {
    ds::Fnv1a64 h;
    for (char c : s) h.byte(static_cast<std::uint8_t>(c));
    return h.value();
  };
  CHECK(fnv("") == 0xcbf29ce484222325ULL);
  CHECK(fnv("a") == 0xaf63dc4c8601ec8cULL);
  CHECK(fnv("foobar") == 0x85944171f73967e8ULL);
}

TEST_CASE("an episode's digest is written with it and changes with any byte of its content", "[dataset]") {
  const fs::path dir = manisoft::test::scratch_dir("manisoft_dataset_digest");
  const ds::Episode e = make_episode(2, 9, "ARR", "clean");
  ds::write_episode(dir / "demo_2.hdf5", e);
  const ds::Episode back = ds::read_episode(dir / "demo_2.hdf5", 2);
  CHECK(back.digest == ds::episode_digest(e));
  CHECK(back.digest.starts_with("fnv1a64:"));
  CHECK(back.digest.size() == 8 + 16);
  CHECK_NOTHROW(ds::check_digest(dir / "demo_2.hdf5", back));
  // One bit of the lowest mantissa byte of one float32 observation: still finite, still in range.
  ds::Episode changed = back;
  float value = static_cast<float>(changed.observations["ee_pose"](4, 2));
  std::uint32_t bits;
  std::memcpy(&bits, &value, 4);
  bits ^= 1u;
  std::memcpy(&value, &bits, 4);
  changed.observations["ee_pose"](4, 2) = value;
  CHECK_THROWS_WITH(ds::check_digest(dir / "demo_2.hdf5", changed), Catch::Contains("demo_2.hdf5: /data/demo_2: content digest mismatch"));
  changed = back;
  changed.dones[0] = 255;
  CHECK_THROWS_WITH(ds::check_digest(dir / "demo_2.hdf5", changed), Catch::Contains("content digest mismatch"));
  changed = back;
  changed.text["setting"] = "randomized";
  CHECK_THROWS_WITH(ds::check_digest(dir / "demo_2.hdf5", changed), Catch::Contains("content digest mismatch"));
  changed = back;
  changed.digest.clear();
  CHECK_THROWS_WITH(ds::check_digest(dir / "demo_2.hdf5", changed), Catch::Contains("missing attribute 'digest'"));
  // Rewriting what was read gives the same digest (the stored one is not copied, it is recomputed).
  ds::write_episode(dir / "again.hdf5", back);
  CHECK(ds::read_episode(dir / "again.hdf5", 2).digest == back.digest);
}

TEST_CASE("the index links every episode, splits 4:1 per stratum, and verify_dataset checks it", "[dataset]") {
  const fs::path dir = manisoft::test::scratch_dir("manisoft_dataset_index");
  fs::remove_all(dir);
  fs::create_directories(ds::episode_folder(dir));
  // Strata: COLL/clean = {0, 1, 2, 3, 4, 7}, ALN/randomized = {5, 6}; written out of order.
  const std::vector<std::pair<long, std::string>> plan{{6, "ALN"}, {0, "COLL"}, {7, "COLL"}, {1, "COLL"},
                                                       {5, "ALN"},  {2, "COLL"}, {3, "COLL"}, {4, "COLL"}};
  long steps = 0;
  double action_sum = 0;
  for (const auto& [k, task] : plan) {
    const ds::Episode e = make_episode(k, 5 + k, task, task == "COLL" ? "clean" : "randomized");
    steps += e.steps();
    action_sum += e.actions.sum();
    ds::write_episode(ds::episode_file(dir, k), e);
  }
  // A generator killed mid-write leaves only a partial file: ignored by the index, counted by verify.
  std::ofstream(ds::episode_file(dir, 8).string() + ds::partial_suffix) << "half an episode";
  CHECK_THROWS_WITH(ds::write_index(dir, "{}", 9), Catch::Contains("demo_8.hdf5: missing (8 of 9 episodes complete)"));
  CHECK_FALSE(fs::exists(ds::index_file(dir)));

  ds::write_index(dir, R"({"env_name": "ManiSoft", "horizon": 1500})", 8);
  const ds::VerifyReport report = ds::verify_dataset(dir);
  CHECK(report.episodes == 8);
  CHECK(report.steps == steps);
  CHECK(report.partial_files == 1);
  // Within each stratum in index order every fifth is validation: COLL/clean -> the fifth is 4.
  CHECK(report.train == 7);
  CHECK(report.valid == 1);
  const ds::h5::File index = ds::h5::File::open(ds::index_file(dir).string());
  CHECK(index.read_strings("/mask/valid") == std::vector<std::string>{"demo_4"});
  CHECK(index.read_numeric_attribute<std::int64_t>("/data", "total") == steps);

  // h5py (no code of ours) reads the index the way robomimic does.
  const fs::path log = dir / "python.log";
  const int code = manisoft::test::run_command("/usr/bin/python3", std::string(MANISOFT_READ_DATASET_PY) + " " + dir.string(),
                                               log.string());
  const std::string text = manisoft::test::slurp(log.string());
  INFO(text);
  REQUIRE(code == 0);
  CHECK_THAT(text, Catch::Contains("demos 8 steps " + std::to_string(steps) + " train 7 valid 1"));
  std::ostringstream expected_sum;
  expected_sum.precision(6);
  expected_sum << std::fixed << "action sum " << action_sum;
  CHECK_THAT(text, Catch::Contains(expected_sum.str()));

#ifdef MANISOFT_VERIFY_DATASET
  // The program checks the expert schema too: these synthetic episodes carry no scene.
  CHECK(manisoft::test::run_command(MANISOFT_VERIFY_DATASET, dir.string(), log.string()) == 1);
  CHECK_THAT(manisoft::test::slurp(log.string()), Catch::Contains("demo_0.hdf5: /data/demo_0: missing attribute 'failure'"));
#endif

  // A damaged episode makes verify fail naming that file.
  fs::resize_file(ds::episode_file(dir, 2), fs::file_size(ds::episode_file(dir, 2)) / 2);
  CHECK_THROWS_WITH(ds::verify_dataset(dir), Catch::Contains("demo_2.hdf5"));
#ifdef MANISOFT_VERIFY_DATASET
  CHECK(manisoft::test::run_command(MANISOFT_VERIFY_DATASET, "--no-such-flag", log.string()) == 2);
  CHECK(manisoft::test::run_command(MANISOFT_VERIFY_DATASET, dir.string() + " --sample 2", log.string()) == 1);
  CHECK_THAT(manisoft::test::slurp(log.string()), Catch::Contains("--sample 2 needs --replay"));
#endif
}
