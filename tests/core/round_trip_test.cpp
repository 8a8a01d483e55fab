// Every model in examples/ survives a save and a load: load -> save -> load
// gives the same document (to_json), and saving the reloaded model again
// writes the very same bytes. One test per example file, so a new example is
// covered by adding it to examples/.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "io/model_file.hpp"
#include "study/files.hpp"
#include "test_util.hpp"

namespace codyna::test {
namespace {

namespace fs = std::filesystem;

// The names of examples/*.json, sorted.
std::vector<std::string> example_files() {
  std::vector<std::string> names;
  for (const fs::directory_entry& e : fs::directory_iterator(CODYNA_EXAMPLES_DIR))
    if (e.is_regular_file() && e.path().extension() == ".json") names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  EXPECT_TRUE(in) << "cannot read " << path;
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// A fresh, empty directory, removed at the end of the test.
class ScratchDir {
 public:
  ScratchDir() {
    const auto* info = testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->test_suite_name()) + "_" + info->name();
    std::replace_if(name.begin(), name.end(), [](char c) { return !std::isalnum(static_cast<unsigned char>(c)); }, '_');
    path_ = fs::temp_directory_path() / ("codyna_" + name + "_" + std::to_string(std::random_device{}()));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

class ExampleRoundTrip : public testing::TestWithParam<std::string> {};

TEST_P(ExampleRoundTrip, SaveLoadGivesSameSpecAndSameBytes) {
  const std::string source = example_path(GetParam());
  const ScratchDir dir;
  const std::string first = (dir.path() / "first.json").string();
  const std::string second = (dir.path() / "second.json").string();

  // moved to another folder, its relative file references (the sedan's .tir) are rewritten
  const ModelSpec original = study_rebase_paths(load_model_spec(source), source, first);
  save_model_spec(original, first);
  const ModelSpec reloaded = load_model_spec(first);
  const nlohmann::json a = to_json(original), b = to_json(reloaded);
  EXPECT_EQ(a, b) << "load -> save -> load changed " << GetParam() << "; diff (RFC 6902) "
                  << nlohmann::json::diff(a, b).dump();

  save_model_spec(reloaded, second);
  const std::string text1 = read_bytes(first), text2 = read_bytes(second);
  EXPECT_FALSE(text1.empty());
  EXPECT_EQ(text1, text2) << "a second save of " << GetParam() << " wrote different bytes";

  // what was written still compiles like the original
  EXPECT_NO_THROW((void)compile(reloaded, first));
}

std::string test_name(const testing::TestParamInfo<std::string>& info) {
  std::string name = info.param.substr(0, info.param.size() - 5);  // without ".json"
  std::replace_if(name.begin(), name.end(), [](char c) { return !std::isalnum(static_cast<unsigned char>(c)); }, '_');
  return name;
}

INSTANTIATE_TEST_SUITE_P(Examples, ExampleRoundTrip, testing::ValuesIn(example_files()), test_name);

TEST(RebasePaths, RelativeReferencesNameTheSameFilesFromTheNewFolder) {
  ModelSpec spec = load_model_spec(example_path("sedan.json"));
  spec.analysis.controller_file = "gains/k.mat";
  spec.analysis.export_dir = "/abs/out";
  SignalSpec r;
  r.type = "file";
  r.file = "road.csv";
  spec.analysis.references.push_back(r);
  const ModelSpec moved = study_rebase_paths(spec, "/a/b/model.json", "/a/c/d/copy.json");
  for (const EffectSpec& e : moved.effects)
    if (e.type == EffectType::Tire) EXPECT_EQ(e.file, "../../b/tires/MagicFormula61_Paramerters.tir");
  EXPECT_EQ(moved.analysis.controller_file, "../../b/gains/k.mat");
  EXPECT_EQ(moved.analysis.export_dir, "/abs/out");  // absolute: as it was
  EXPECT_EQ(moved.analysis.references.at(0).file, "../../b/road.csv");
  // into a subfolder and back: the same text; the same folder: untouched
  const ModelSpec back = study_rebase_paths(moved, "/a/c/d/copy.json", "/a/b/again.json");
  EXPECT_EQ(back.analysis.controller_file, "gains/k.mat");
  EXPECT_EQ(back.analysis.references.at(0).file, "road.csv");
  EXPECT_EQ(to_json(study_rebase_paths(spec, "/a/b/model.json", "/a/b/other.json")), to_json(spec));
  // and the sedan saved elsewhere compiles there, its tires found
  const ScratchDir dir;
  const std::string copy = (dir.path() / "sub" / "sedan_copy.json").string();
  fs::create_directories(dir.path() / "sub");
  save_model_spec(study_rebase_paths(load_model_spec(example_path("sedan.json")), example_path("sedan.json"), copy), copy);
  EXPECT_NO_THROW((void)compile(load_model_spec(copy), copy));
}

TEST(ExampleFiles, AreFound) { EXPECT_GE(example_files().size(), 5u) << CODYNA_EXAMPLES_DIR; }

}  // namespace
}  // namespace codyna::test
