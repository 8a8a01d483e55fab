// The shard K of N a front end is given (study_parse_shard, study_check_shard in sweep.hpp):
// "K/N", or "slurm" from a Slurm job array's variables. One reader for `codyna sweep --shard`
// and the Python module's Study.sweep(shard=), so that both accept and refuse the same values.
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "study/sweep.hpp"

namespace codyna {

namespace {

// digits only, at most 18 of them (no sign, no blanks: " 1", "+1" and "1e3" are not whole numbers here)
bool whole_number(const std::string& text, long long& value) {
  if (text.empty() || text.size() > 18 || text.find_first_not_of("0123456789") != std::string::npos) return false;
  value = std::stoll(text);
  return true;
}

// what the user wrote, in the front end's spelling: the CLI's bare text, Python's quoted str
std::string as_given(const std::string& text, OptionStyle style) {
  return style == OptionStyle::Flag ? text : "'" + text + "'";
}

}  // namespace

SweepShard study_check_shard(long long index, long long count, OptionStyle style, const std::string& given) {
  if (index >= 0 && count >= 1 && index < count) return {index, count};
  if (style == OptionStyle::Flag)
    throw std::invalid_argument(option_name(style, "shard") + " " + given + ": expected K/N with 0 <= K < N, or slurm");
  throw std::invalid_argument(option_name(style, "shard") +
                              ": expected (K, N), \"K/N\" or \"slurm\" with N >= 1 and 0 <= K < N (K counts from 0, as "
                              "codyna sweep --shard K/N), got " + given);
}

SweepShard study_parse_shard(const std::string& text, OptionStyle style) {
  if (text == "slurm") {
    const std::string option = style == OptionStyle::Flag ? "--shard slurm" : "shard='slurm'";
    const char* id = std::getenv("SLURM_ARRAY_TASK_ID");
    const char* count = std::getenv("SLURM_ARRAY_TASK_COUNT");
    const char* min = std::getenv("SLURM_ARRAY_TASK_MIN");
    if (!id || !count) {
      const std::string missing = !id && !count ? "SLURM_ARRAY_TASK_ID and SLURM_ARRAY_TASK_COUNT are not set"
                                  : !id         ? "SLURM_ARRAY_TASK_ID is not set"
                                                : "SLURM_ARRAY_TASK_COUNT is not set";
      throw std::invalid_argument(option + ": " + missing + " (not in a Slurm job array)");
    }
    long long k = 0, n = 0, first = 0;
    const auto read = [&](const char* name, const char* value, long long& v) {
      if (!whole_number(value, v))
        throw std::invalid_argument(option + ": " + name + "=" + value + ": expected a whole number (0 or more)");
    };
    read("SLURM_ARRAY_TASK_ID", id, k);
    read("SLURM_ARRAY_TASK_COUNT", count, n);
    if (min) read("SLURM_ARRAY_TASK_MIN", min, first);
    const std::string from_min = min ? " - SLURM_ARRAY_TASK_MIN=" + std::string(min) : "";
    if (n < 1 || k < first || k - first >= n)
      throw std::invalid_argument(option + ": SLURM_ARRAY_TASK_ID=" + std::string(id) + from_min + " is not a shard of " +
                                  "SLURM_ARRAY_TASK_COUNT=" + count + ": expected 0 <= ID" + (min ? " - MIN" : "") +
                                  " < COUNT (an array of consecutive tasks, e.g. --array=0-15, with no step or gaps)");
    return {k - first, n};
  }
  long long k = -1, n = 0;
  const std::size_t slash = text.find('/');
  if (slash == std::string::npos || !whole_number(text.substr(0, slash), k) || !whole_number(text.substr(slash + 1), n))
    k = -1, n = 0;
  return study_check_shard(k, n, style, as_given(text, style));
}

SweepJob study_sweep_own_variants(SweepJob&& job, std::vector<long long>& indices) {
  indices.clear();
  if (job.shard_count == 0) return std::move(job);
  std::vector<SweepVariant> mine;
  long long worst = -1, largest = -1;
  for (long long i = 0; i < static_cast<long long>(job.variants.size()); ++i) {
    if (!job.in_shard(i)) continue;
    if (i == job.worst) worst = static_cast<long long>(mine.size());
    if (i == job.largest_input) largest = static_cast<long long>(mine.size());
    indices.push_back(i);
    mine.push_back(std::move(job.variants[static_cast<std::size_t>(i)]));
  }
  job.variants = std::move(mine);
  job.worst = worst;
  job.largest_input = largest;
  return std::move(job);
}

}  // namespace codyna
