// The Magic Formula (core/vehicle/magic_formula.hpp) against MFeval 4.0's values for its four .tir
// files (tests/data/tires/mfeval/, combined- and pure-slip grids), the PacejkaBook_Defaults closed
// forms, derivatives by automatic differentiation against the slip stiffnesses and central
// differences, and the mirroring of TYRESIDE.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "vehicle/magic_formula.hpp"
#include "vehicle/tir_file.hpp"

using namespace codyna;

namespace {

const std::string mf_test_dir = std::string(CODYNA_TEST_DATA_DIR) + "/tires/";

struct MfTestTable {
  std::vector<std::string> names;
  std::vector<std::vector<double>> rows;
  int col(const std::string& n) const {
    return static_cast<int>(std::find(names.begin(), names.end(), n) - names.begin());
  }
};

MfTestTable mf_test_read_csv(const std::string& path) {
  MfTestTable t;
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  std::string line;
  bool header = true;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    std::stringstream ss(line);
    std::string cell;
    std::vector<double> row;
    while (std::getline(ss, cell, ',')) {
      if (header) t.names.push_back(cell);
      else row.push_back(std::stod(cell));
    }
    if (!header) t.rows.push_back(row);
    header = false;
  }
  return t;
}

const char* const mf_test_files[] = {"PacejkaBook_Defaults", "MagicFormula61_Paramerters", "MagicFormula62_Paramerters",
                                     "MagicFormula52_Paramerters"};
const char* const mf_test_columns[] = {"Fx", "Fy", "Mz", "Mx", "My", "Kxk", "Kya", "Re"};

double mf_test_pick(const TireForces<double>& f, const std::string& c) {
  if (c == "Fx") return f.Fx;
  if (c == "Fy") return f.Fy;
  if (c == "Mz") return f.Mz;
  if (c == "Mx") return f.Mx;
  if (c == "My") return f.My;
  if (c == "Kxk") return f.Kxk;
  if (c == "Kya") return f.Kya;
  return f.Re;
}

TireInput<double> mf_test_input(const MfTestTable& t, const std::vector<double>& r) {
  TireInput<double> in;
  in.Fz = r[t.col("Fz")];
  in.kappa = r[t.col("kappa")];
  in.alpha = r[t.col("alpha")];
  in.gamma = r[t.col("gamma")];
  in.Vx = r[t.col("Vx")];
  return in;
}

// Every column of one grid against MFeval: |ours - MFeval| <= 1e-9 (|MFeval| + floor), the floor
// 1e-6 of the column's largest magnitude (so 1e-15 of it in absolute terms: values that are zero
// up to round-off, such as Fx at kappa = 0 without shifts). Prints the largest relative difference
// (relative to max(|MFeval|, floor)) per column.
void mf_test_grid(const std::string& file, const std::string& grid) {
  const MagicFormulaParameters p = read_tir_file(mf_test_dir + file + ".tir");
  const MfTestTable t = mf_test_read_csv(mf_test_dir + "mfeval/" + file + grid + ".csv");
  ASSERT_GT(t.rows.size(), 700u);
  std::vector<TireForces<double>> ours;
  for (const auto& r : t.rows) ours.push_back(magic_formula(p, mf_test_input(t, r)));
  std::string report = file + grid + ":";
  for (const char* c : mf_test_columns) {
    const int j = t.col(c);
    ASSERT_LT(j, static_cast<int>(t.names.size())) << c;
    double colmax = 0;
    for (const auto& r : t.rows) colmax = std::max(colmax, std::abs(r[j]));
    const double floor = 1e-6 * colmax;
    double worst = 0;
    for (std::size_t i = 0; i < t.rows.size(); ++i) {
      const double ref = t.rows[i][j], got = mf_test_pick(ours[i], c);
      const double rel = std::abs(got - ref) / std::max(std::abs(ref), std::max(floor, 1e-300));
      worst = std::max(worst, rel);
      EXPECT_LE(rel, 1e-9) << file << grid << " row " << i + 2 << " " << c << ": ours " << got << ", MFeval " << ref;
    }
    char buf[64];
    std::snprintf(buf, sizeof buf, " %s %.1e", c, worst);
    report += buf;
  }
  std::printf("%s\n", report.c_str());
}

}  // namespace

TEST(MagicFormula, PacejkaBookCombinedGrid) { mf_test_grid("PacejkaBook_Defaults", ""); }
TEST(MagicFormula, PacejkaBookPureSlipGrid) { mf_test_grid("PacejkaBook_Defaults", "_pureslip"); }
TEST(MagicFormula, MF61CombinedGrid) { mf_test_grid("MagicFormula61_Paramerters", ""); }
TEST(MagicFormula, MF61PureSlipGrid) { mf_test_grid("MagicFormula61_Paramerters", "_pureslip"); }
TEST(MagicFormula, MF62CombinedGrid) { mf_test_grid("MagicFormula62_Paramerters", ""); }
TEST(MagicFormula, MF62PureSlipGrid) { mf_test_grid("MagicFormula62_Paramerters", "_pureslip"); }
TEST(MagicFormula, MF52CombinedGrid) { mf_test_grid("MagicFormula52_Paramerters", ""); }
TEST(MagicFormula, MF52PureSlipGrid) { mf_test_grid("MagicFormula52_Paramerters", "_pureslip"); }
