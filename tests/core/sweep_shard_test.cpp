// The shard a front end is given (core/study/sweep_shard.cpp, issue 22): "K/N" and "slurm" read
// once for `codyna sweep --shard` and Study.sweep(shard=). The CLI's messages are the ones
// cmd_sweep.cpp printed before the reader moved here, byte for byte; the Slurm variables are
// set and restored around each case.
#include <gtest/gtest.h>

#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string>

#include "study/sweep.hpp"

namespace codyna {
namespace {

// sets (or unsets, with nullopt) the three Slurm array variables; restores them when done
class SlurmArray {
 public:
  SlurmArray(std::optional<std::string> id, std::optional<std::string> count, std::optional<std::string> min) {
    for (int i = 0; i < 3; ++i) {
      const char* old = std::getenv(kNames[i]);
      saved_[i] = old ? std::optional<std::string>(old) : std::nullopt;
    }
    set(0, id);
    set(1, count);
    set(2, min);
  }
  ~SlurmArray() {
    for (int i = 0; i < 3; ++i) set(i, saved_[i]);
  }
  SlurmArray(const SlurmArray&) = delete;
  SlurmArray& operator=(const SlurmArray&) = delete;

 private:
  static constexpr const char* kNames[3] = {"SLURM_ARRAY_TASK_ID", "SLURM_ARRAY_TASK_COUNT", "SLURM_ARRAY_TASK_MIN"};
  static void set(int i, const std::optional<std::string>& v) {
    if (v)
      setenv(kNames[i], v->c_str(), 1);
    else
      unsetenv(kNames[i]);
  }
  std::optional<std::string> saved_[3];
};

std::string shard_refusal(const std::string& text, OptionStyle style) {
  try {
    const SweepShard s = study_parse_shard(text, style);
    return "accepted " + std::to_string(s.index) + "/" + std::to_string(s.count);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
}

void expect_shard(const std::string& text, long long k, long long n) {
  const SweepShard s = study_parse_shard(text, OptionStyle::Flag);
  EXPECT_EQ(s.index, k) << text;
  EXPECT_EQ(s.count, n) << text;
}

TEST(SweepShard, KOfNIsReadAndCheckedWithTheCommandsMessage) {
  const SlurmArray none(std::nullopt, std::nullopt, std::nullopt);
  expect_shard("0/2", 0, 2);
  expect_shard("1/2", 1, 2);
  expect_shard("0/1", 0, 1);
  expect_shard("15/16", 15, 16);
  expect_shard("999999999999999998/999999999999999999", 999999999999999998LL, 999999999999999999LL);
  for (const std::string bad : {"2/2", "-1/2", "1/0", "1 /2", " 1/2", "+1/2", "0/2/3", "a/b", "/2", "1/", "", "1", "0x1/2",
                                "1/1e3", "1234567890123456789/1234567890123456790"})
    EXPECT_EQ(shard_refusal(bad, OptionStyle::Flag), "--shard " + bad + ": expected K/N with 0 <= K < N, or slurm");
  EXPECT_EQ(shard_refusal("2/2", OptionStyle::Keyword),
            "shard: expected (K, N), \"K/N\" or \"slurm\" with N >= 1 and 0 <= K < N (K counts from 0, as codyna sweep "
            "--shard K/N), got '2/2'");
  // the (K, N) check alone, as the Python module's tuple is checked
  EXPECT_EQ(study_check_shard(3, 4, OptionStyle::Keyword, "(3, 4)").index, 3);
  EXPECT_EQ(study_check_shard(3, 4, OptionStyle::Keyword, "(3, 4)").count, 4);
  for (const auto& [k, n] : {std::pair{4LL, 4LL}, {-1LL, 4LL}, {0LL, 0LL}, {0LL, -2LL}})
    EXPECT_THROW(study_check_shard(k, n, OptionStyle::Flag, "x"), std::invalid_argument) << k << "/" << n;
}

TEST(SweepShard, SlurmIsTheArrayTasksIdFromItsMinOfItsCount) {
  {
    const SlurmArray task("1", "2", std::nullopt);  // no MIN: IDs from 0
    expect_shard("slurm", 1, 2);
  }
  {
    const SlurmArray task("1", "2", "0");
    expect_shard("slurm", 1, 2);
  }
  {
    const SlurmArray task("2", "2", "1");  // --array=1-2: task 2 is shard 1 of 2
    expect_shard("slurm", 1, 2);
  }
  {
    const SlurmArray task("107", "16", "100");  // --array=100-115
    expect_shard("slurm", 7, 16);
  }
}

TEST(SweepShard, SlurmOutsideAnArrayOrWithBadValuesIsRefusedNamingTheVariables) {
  {
    const SlurmArray none(std::nullopt, std::nullopt, std::nullopt);
    EXPECT_EQ(shard_refusal("slurm", OptionStyle::Flag),  // the command's message before the move, byte for byte
              "--shard slurm: SLURM_ARRAY_TASK_ID and SLURM_ARRAY_TASK_COUNT are not set (not in a Slurm job array)");
    EXPECT_EQ(shard_refusal("slurm", OptionStyle::Keyword),
              "shard='slurm': SLURM_ARRAY_TASK_ID and SLURM_ARRAY_TASK_COUNT are not set (not in a Slurm job array)");
  }
  {
    const SlurmArray task("1", std::nullopt, "0");
    EXPECT_EQ(shard_refusal("slurm", OptionStyle::Flag), "--shard slurm: SLURM_ARRAY_TASK_COUNT is not set (not in a Slurm job array)");
  }
  {
    const SlurmArray task(std::nullopt, "2", std::nullopt);
    EXPECT_EQ(shard_refusal("slurm", OptionStyle::Flag), "--shard slurm: SLURM_ARRAY_TASK_ID is not set (not in a Slurm job array)");
  }
  {
    const SlurmArray task("x1", "2", std::nullopt);
    EXPECT_EQ(shard_refusal("slurm", OptionStyle::Flag), "--shard slurm: SLURM_ARRAY_TASK_ID=x1: expected a whole number (0 or more)");
  }
  {
    const SlurmArray task("1", "", std::nullopt);
    EXPECT_EQ(shard_refusal("slurm", OptionStyle::Keyword), "shard='slurm': SLURM_ARRAY_TASK_COUNT=: expected a whole number (0 or more)");
  }
  {
    const SlurmArray task("1", "2", "-1");
    EXPECT_EQ(shard_refusal("slurm", OptionStyle::Flag), "--shard slurm: SLURM_ARRAY_TASK_MIN=-1: expected a whole number (0 or more)");
  }
  {
    // --array=0-15:4 (a step): IDs 0, 4, 8, 12 of COUNT 4 are no set of shards
    const SlurmArray task("12", "4", "0");
    EXPECT_EQ(shard_refusal("slurm", OptionStyle::Flag),
              "--shard slurm: SLURM_ARRAY_TASK_ID=12 - SLURM_ARRAY_TASK_MIN=0 is not a shard of SLURM_ARRAY_TASK_COUNT=4: "
              "expected 0 <= ID - MIN < COUNT (an array of consecutive tasks, e.g. --array=0-15, with no step or gaps)");
  }
  {
    const SlurmArray task("0", "0", std::nullopt);
    EXPECT_EQ(shard_refusal("slurm", OptionStyle::Flag),
              "--shard slurm: SLURM_ARRAY_TASK_ID=0 is not a shard of SLURM_ARRAY_TASK_COUNT=0: expected 0 <= ID < COUNT "
              "(an array of consecutive tasks, e.g. --array=0-15, with no step or gaps)");
  }
  {
    const SlurmArray task("3", "4", "5");  // below MIN
    EXPECT_THROW(study_parse_shard("slurm", OptionStyle::Flag), std::invalid_argument);
  }
}

}  // namespace
}  // namespace codyna
