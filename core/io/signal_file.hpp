// Time series for reference and disturbance signals (a SignalSpec of type "file"):
//
//   CSV   a header line naming the two columns (any names, e.g. "t,value"), then one row
//         "t,value" per sample: numbers in the C locale, separated by one comma; blank
//         lines and a trailing '\r' are ignored
//   MAT   (name ending in .mat) the vectors t and value (rows or columns, double or single,
//         the same length), MAT v5/v7 or v7.3
//
// Checked: at least one sample, every number finite, times strictly increasing. An error is a
// std::invalid_argument naming the file, the column (CSV) or variable (MAT) and the row
// ("ref.csv: row 3 (line 4), column value: expected a finite number, got \"abc\"").
// The signal is then piecewise linear through the samples and held beyond the ends
// (signal_value of a table).
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace codyna {

std::vector<std::pair<double, double>> read_signal_file(const std::string& path);

}  // namespace codyna
