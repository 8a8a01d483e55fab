// The files of a parameter study (io/sweep_data.hpp's records): the HDF5 results, the CSV
// table, NAME.mat with its NAME.m loader (docs/parameter-studies.md, "The files"), each checked by
// io/output_guard.hpp against the model file first and written atomically; and the journal a
// running study appends one line to per finished variant (numbers exact, NaN's bits included),
// read back when the study resumes and joined by sweep-merge.
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "io/sweep_data.hpp"

namespace codyna {

// the CSV's first bytes (what io/output_guard.hpp tells a sweep CSV by)
inline constexpr const char* kSweepCsvHead = "variant,status";

void write_sweep_hdf5(const SweepJob& job, const std::string& path);
void write_sweep_csv(const SweepJob& job, const std::string& path);
// DIR/NAME.mat and DIR/NAME.m; NAME must be a MATLAB identifier
void write_sweep_mat(const SweepJob& job, const std::string& mat_path);

// one journal line of variant i, and the variant read back from a line's JSON
std::string sweep_journal_line(long long i, const SweepVariant& v);
SweepVariant sweep_journal_variant(const nlohmann::json& j);
// true when `path` is missing, empty, or begins as a codyna sweep journal does
bool is_sweep_journal(const std::string& path);
// the journal's hash of a text, chained from h (FNV-1a then sweep_mix64)
std::uint64_t sweep_hash_text(std::uint64_t h, const std::string& text);

}  // namespace codyna
