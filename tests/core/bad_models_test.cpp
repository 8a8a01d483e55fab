// The project's corpus of bad models (tests/data/bad_models, one per category of
// hostile input): each is refused with a ModelError naming the file, the field
// path and what was expected; never a crash, never accepted.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "io/model_file.hpp"
#include "dynamics/prepare.hpp"
#include "model/errors.hpp"

namespace {

struct Case {
  std::string file, path, phrase;
};

std::vector<Case> manifest() {
  std::ifstream in(std::string(CODYNA_TEST_DATA_DIR) + "/bad_models/expected.tsv");
  std::vector<Case> cases;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    Case c;
    std::getline(s, c.file, '\t');
    std::getline(s, c.path, '\t');
    std::getline(s, c.phrase);
    cases.push_back(c);
  }
  return cases;
}

}  // namespace

TEST(BadModels, EveryCategoryIsRefusedWithItsFieldPath) {
  const std::string dir = std::string(CODYNA_TEST_DATA_DIR) + "/bad_models";
  const std::vector<Case> cases = manifest();
  ASSERT_GE(cases.size(), 18u);
  std::size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) files += e.path().extension() == ".json";
  EXPECT_EQ(files, cases.size()) << "every file in bad_models/ has a line in expected.tsv";
  for (const Case& c : cases) {
    const std::string path = dir + "/" + c.file;
    try {
      codyna::compile(codyna::load_model_spec(path), path);
      ADD_FAILURE() << c.file << " was accepted";
    } catch (const codyna::ModelError& e) {
      EXPECT_EQ(e.file(), path) << c.file;
      EXPECT_EQ(e.path(), c.path) << c.file << ": " << e.what();
      EXPECT_NE(std::string(e.what()).find(c.phrase), std::string::npos) << c.file << ": " << e.what();
    }
  }
}
