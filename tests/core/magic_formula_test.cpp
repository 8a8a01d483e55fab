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
  MagicFormulaOptions no_limits;
  no_limits.limits = false;
  for (const auto& r : t.rows) {
    ours.push_back(magic_formula(p, mf_test_input(t, r)));
    // no point of the grids reaches a limit: use mode 211 gives the same
    const TireForces<double> free = magic_formula(p, mf_test_input(t, r), no_limits);
    EXPECT_EQ(free.Fx, ours.back().Fx);
    EXPECT_EQ(free.Fy, ours.back().Fy);
    EXPECT_EQ(free.Mz, ours.back().Mz);
  }
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

// PacejkaBook_Defaults.tir (every shift and curvature 0, FNOMIN 4000 N) at Fz = FNOMIN, pure slip,
// gamma 0: the closed forms of docs/VEHICLES.md. MFeval's guard terms (epsilon 1e-6 in the
// denominators of B_x, B_y) move the forces by about 3e-7 N.
TEST(MagicFormula, PacejkaBookClosedForms) {
  const MagicFormulaParameters p = read_tir_file(mf_test_dir + "PacejkaBook_Defaults.tir");
  TireInput<double> in;
  in.Fz = 4000;
  in.Vx = 16.7;
  const TireForces<double> f0 = magic_formula(p, in);
  EXPECT_NEAR(f0.Kxk, 64000.0, 1e-9 * 64000);
  EXPECT_NEAR(f0.Kya, -48000.0, 1e-9 * 48000);
  EXPECT_NEAR(f0.Kya, 4000 * -15 * std::sin(2 * std::atan(0.5)), 1e-9 * 48000);  // PKY1 Fz0 sin(PKY4 atan(Fz / (PKY2 Fz0)))
  in.kappa = 0.05;
  const TireForces<double> fx = magic_formula(p, in);
  EXPECT_NEAR(fx.Fx, 4000 * std::sin(1.6 * std::atan(0.5)), 1e-6);  // 2702.57092495 N
  EXPECT_NEAR(fx.Fx, 2702.57092465, 1e-8);                         // MFeval's value
  EXPECT_NEAR(fx.Fy, 0.0, 1e-9);
  in.kappa = 0;
  in.alpha = 0.05;
  const TireForces<double> fy = magic_formula(p, in);
  const double By = -48000.0 / (1.3 * 4000);
  EXPECT_NEAR(fy.Fy, 4000 * std::sin(1.3 * std::atan(By * 0.05)), 1e-6);  // -2131.95894624 N
  EXPECT_NEAR(fy.Fy, -2131.95894592, 1e-8);
  // over the pure-slip sweeps at gamma = 0: the closed forms to 1e-6 N
  for (double Fz : {2000.0, 4000.0, 6000.0}) {
    for (int i = 0; i <= 60; ++i) {
      const double s = -0.3 + 0.01 * i;
      TireInput<double> a;
      a.Fz = Fz;
      a.Vx = 16.7;
      a.kappa = s;
      const double dfz = (Fz - 4000) / 4000, mux = 1.0 - 0.1 * dfz;  // PDX1 + PDX2 dfz
      const double Bx = 16 * Fz / (1.6 * mux * Fz);                   // PKX1 Fz / (C D)
      EXPECT_NEAR(magic_formula(p, a).Fx, mux * Fz * std::sin(1.6 * std::atan(Bx * s)), 1e-6) << Fz << " " << s;
    }
  }
}

namespace {

using MfAD = Eigen::AutoDiffScalar<Eigen::VectorXd>;

// inputs (Fz, kappa, alpha, gamma) seeded as the 4 independent variables
TireInput<MfAD> mf_test_seed(double Fz, double kappa, double alpha, double gamma, double Vx) {
  TireInput<MfAD> in;
  in.Fz = MfAD(Fz, Eigen::VectorXd::Unit(4, 0));
  in.kappa = MfAD(kappa, Eigen::VectorXd::Unit(4, 1));
  in.alpha = MfAD(alpha, Eigen::VectorXd::Unit(4, 2));
  in.gamma = MfAD(gamma, Eigen::VectorXd::Unit(4, 3));
  in.Vx = MfAD(Vx);
  return in;
}

}  // namespace

// The derivatives by automatic differentiation at zero slip equal the slip stiffnesses the formula
// reports (the book file: no shifts, so the slope at zero slip is B C D itself).
TEST(MagicFormula, AutodiffSlopesAtZeroSlipAreTheStiffnesses) {
  const MagicFormulaParameters p = read_tir_file(mf_test_dir + "PacejkaBook_Defaults.tir");
  for (double Fz : {2000.0, 4000.0, 6000.0}) {
    const TireForces<MfAD> f = magic_formula(p, mf_test_seed(Fz, 0, 0, 0, 16.7));
    EXPECT_NEAR(f.Fx.derivatives()[1], f.Kxk.value(), 1e-9 * std::abs(f.Kxk.value())) << Fz;
    EXPECT_NEAR(f.Fy.derivatives()[2], f.Kya.value(), 1e-9 * std::abs(f.Kya.value())) << Fz;
    // and the double evaluation gives the same values
    TireInput<double> d;
    d.Fz = Fz;
    d.Vx = 16.7;
    const TireForces<double> g = magic_formula(p, d);
    EXPECT_EQ(g.Kxk, f.Kxk.value());
    EXPECT_EQ(g.Kya, f.Kya.value());
  }
}

// Automatic differentiation against (fourth-order) central differences at random points near the grids' rows
// (offset off the grid so that no point sits on a kink: |gamma| at 0, sign(kappa_x) at 0), for
// all four files, every output force and moment and the inputs Fz, kappa, alpha, gamma: agreement
// to 1e-6 of the derivative (floor: 1e-3 of the largest of that derivative over the points).
TEST(MagicFormula, AutodiffMatchesCentralDifferences) {
  std::mt19937 rng(20261129);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (const char* file : mf_test_files) {
    const MagicFormulaParameters p = read_tir_file(mf_test_dir + file + ".tir");
    const MfTestTable t = mf_test_read_csv(mf_test_dir + "mfeval/" + file + ".csv");
    struct Sample {
      double x[4];
      double ad[6][4];
      double fd[6][4];
    };
    std::vector<Sample> samples;
    for (int n = 0; n < 25; ++n) {
      const auto& r = t.rows[static_cast<std::size_t>(u(rng) * static_cast<double>(t.rows.size())) % t.rows.size()];
      Sample s;
      s.x[0] = r[t.col("Fz")] * (1 + 0.05 * u(rng));
      s.x[1] = r[t.col("kappa")] + 0.003 + 0.01 * u(rng);
      s.x[2] = r[t.col("alpha")] + 0.003 + 0.01 * u(rng);
      s.x[3] = r[t.col("gamma")] + 0.003 + 0.01 * u(rng);
      const TireForces<MfAD> f = magic_formula(p, mf_test_seed(s.x[0], s.x[1], s.x[2], s.x[3], 16.7));
      const MfAD* outs[6] = {&f.Fx, &f.Fy, &f.Mz, &f.Mx, &f.My, &f.Re};
      for (int o = 0; o < 6; ++o)
        for (int j = 0; j < 4; ++j) s.ad[o][j] = outs[o]->derivatives().size() ? outs[o]->derivatives()[j] : 0.0;
      for (int j = 0; j < 4; ++j) {
        // fourth-order central differences: (8 (f(x+h) - f(x-h)) - (f(x+2h) - f(x-2h))) / (12 h)
        const double h = j == 0 ? 1e-4 * s.x[0] : 1e-5;
        auto eval = [&](double step) {
          double x[4];
          std::copy(s.x, s.x + 4, x);
          x[j] += step;
          TireInput<double> in;
          in.Fz = x[0];
          in.kappa = x[1];
          in.alpha = x[2];
          in.gamma = x[3];
          in.Vx = 16.7;
          const TireForces<double> f = magic_formula(p, in);
          return std::vector<double>{f.Fx, f.Fy, f.Mz, f.Mx, f.My, f.Re};
        };
        const auto p1 = eval(h), m1 = eval(-h), p2 = eval(2 * h), m2 = eval(-2 * h);
        for (int o = 0; o < 6; ++o) s.fd[o][j] = (8 * (p1[o] - m1[o]) - (p2[o] - m2[o])) / (12 * h);
      }
      samples.push_back(s);
    }
    const char* names[6] = {"Fx", "Fy", "Mz", "Mx", "My", "Re"};
    for (int o = 0; o < 6; ++o)
      for (int j = 0; j < 4; ++j) {
        double big = 0;
        for (const Sample& s : samples) big = std::max(big, std::abs(s.ad[o][j]));
        for (const Sample& s : samples)
          EXPECT_LE(std::abs(s.ad[o][j] - s.fd[o][j]), 1e-6 * std::max(std::abs(s.ad[o][j]), 1e-3 * big) + 1e-12)
              << file << " d" << names[o] << "/dx" << j << " at (" << s.x[0] << ", " << s.x[1] << ", " << s.x[2]
              << ", " << s.x[3] << "): AD " << s.ad[o][j] << ", differences " << s.fd[o][j];
      }
  }
}

// TYRESIDE: MFeval evaluates a file as it stands (its tables are the AsFile values). Mounted on the
// other side, a file is mirrored: a RIGHT file on the left gives -Fy, -Mz, -Mx of the same file at
// (-alpha, -gamma), Fx and My as they are; the same coefficients written as a LEFT file and mounted
// on the left give the unmirrored values.
TEST(MagicFormula, TyresideMirrorsLateralForceAndMoments) {
  std::ifstream in(mf_test_dir + "MagicFormula61_Paramerters.tir", std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string right_text = ss.str();
  std::string left_text = right_text;
  const auto at = left_text.find("'RIGHT'");
  ASSERT_NE(at, std::string::npos);
  left_text.replace(at, 7, "'LEFT' ");
  const MagicFormulaParameters right = parse_tir_text(right_text, "right.tir");
  const MagicFormulaParameters left = parse_tir_text(left_text, "left.tir");
  ASSERT_EQ(right.TYRESIDE, TireSide::Right);
  ASSERT_EQ(left.TYRESIDE, TireSide::Left);
  MagicFormulaOptions on_left;
  on_left.mount = TireMount::Left;
  MagicFormulaOptions on_right;
  on_right.mount = TireMount::Right;
  for (double a : {-0.2, 0.0, 0.07})
    for (double g : {-0.04, 0.0, 0.05})
      for (double k : {-0.1, 0.0, 0.05}) {
        TireInput<double> x;
        x.Fz = 6000;
        x.kappa = k;
        x.alpha = a;
        x.gamma = g;
        x.Vx = 16.7;
        TireInput<double> xm = x;
        xm.alpha = -a;
        xm.gamma = -g;
        const TireForces<double> r_file = magic_formula(right, x);
        const TireForces<double> l_file = magic_formula(left, x);
        const TireForces<double> r_on_right = magic_formula(right, x, on_right);
        const TireForces<double> l_on_left = magic_formula(left, x, on_left);
        const TireForces<double> r_on_left = magic_formula(right, x, on_left);
        const TireForces<double> r_mirror_point = magic_formula(right, xm);
        // as the file says: no change, whatever the side written
        EXPECT_EQ(r_file.Fy, l_file.Fy);
        EXPECT_EQ(r_file.Fy, r_on_right.Fy);
        EXPECT_EQ(l_file.Mz, l_on_left.Mz);
        // the other side: mirrored
        EXPECT_EQ(r_on_left.Fy, -r_mirror_point.Fy);
        EXPECT_EQ(r_on_left.Mz, -r_mirror_point.Mz);
        EXPECT_EQ(r_on_left.Mx, -r_mirror_point.Mx);
        EXPECT_EQ(r_on_left.Fx, r_mirror_point.Fx);
        EXPECT_EQ(r_on_left.My, r_mirror_point.My);
        EXPECT_EQ(magic_formula(left, x, on_right).Fy, -r_mirror_point.Fy);
      }
  // a fitted tire is not symmetric: the mirror differs at camber
  TireInput<double> x;
  x.Fz = 6000;
  x.alpha = 0.05;
  x.gamma = 0.05;
  x.Vx = 16.7;
  EXPECT_GT(std::abs(magic_formula(right, x, on_left).Fy - magic_formula(right, x).Fy), 10.0);
}

// The limits of use mode 111 (and their absence in 211): loads above FZMAX and slip angles beyond
// ALPMAX are clamped; at standstill the slips, shifts and forces vanish and derivatives stay finite.
TEST(MagicFormula, LimitsClampAndStandstillIsAtRest) {
  const MagicFormulaParameters p = read_tir_file(mf_test_dir + "MagicFormula61_Paramerters.tir");
  MagicFormulaOptions off;
  off.limits = false;
  TireInput<double> x;
  x.Fz = p.FZMAX;
  x.kappa = 0.1;
  x.alpha = 0.1;
  x.Vx = 16.7;
  const TireForces<double> at_max = magic_formula(p, x);
  x.Fz = 1.3 * p.FZMAX;
  EXPECT_EQ(magic_formula(p, x).Fx, at_max.Fx);
  EXPECT_EQ(magic_formula(p, x).Fy, at_max.Fy);
  EXPECT_NE(magic_formula(p, x, off).Fy, at_max.Fy);
  x.Fz = 5000;
  x.alpha = p.ALPMAX;
  const double fy_max = magic_formula(p, x).Fy;
  x.alpha = p.ALPMAX + 0.2;
  EXPECT_EQ(magic_formula(p, x).Fy, fy_max);
  EXPECT_NE(magic_formula(p, x, off).Fy, fy_max);
  // pressure: 0 stands for the file's INFLPRES
  x.alpha = 0.05;
  TireInput<double> xp = x;
  xp.pressure = p.INFLPRES;
  EXPECT_EQ(magic_formula(p, xp).Fy, magic_formula(p, x).Fy);
  xp.pressure = 1.1 * p.NOMPRES;
  EXPECT_NE(magic_formula(p, xp).Fy, magic_formula(p, x).Fy);
  // standstill
  for (const char* file : mf_test_files) {
    const MagicFormulaParameters q = read_tir_file(mf_test_dir + file + ".tir");
    const TireForces<MfAD> f = magic_formula(q, mf_test_seed(0.8 * q.FNOMIN, 0.05, 0.1, 0.02, 0.0));
    EXPECT_EQ(f.Fx.value(), 0.0) << file;
    EXPECT_EQ(f.Fy.value(), 0.0) << file;
    EXPECT_EQ(f.My.value(), 0.0) << file;
    for (const MfAD* v : {&f.Fx, &f.Fy, &f.Mz, &f.Mx, &f.My, &f.Re})
      for (Eigen::Index j = 0; j < v->derivatives().size(); ++j) EXPECT_TRUE(std::isfinite(v->derivatives()[j])) << file;
    // below VXLOW the forces grow smoothly from zero
    TireInput<double> slow;
    slow.Fz = 0.8 * q.FNOMIN;
    slow.kappa = 0.05;
    slow.alpha = 0.1;
    slow.Vx = 0.5 * q.VXLOW;
    const TireForces<double> s = magic_formula(q, slow);
    slow.Vx = 16.7;
    const TireForces<double> fast = magic_formula(q, slow);
    EXPECT_LT(std::abs(s.Fy), std::abs(fast.Fy)) << file;
    EXPECT_GT(std::abs(s.Fy), 0.0) << file;
  }
}

// Any derivative type works (the template's body is in the header): a fixed-size derivative
// vector gives the same values and derivatives as the dynamic one compiled in the library.
TEST(MagicFormula, FixedSizeAutodiffAgrees) {
  using Fixed = Eigen::AutoDiffScalar<Eigen::Vector4d>;
  const MagicFormulaParameters p = read_tir_file(mf_test_dir + "MagicFormula61_Paramerters.tir");
  TireInput<Fixed> in;
  in.Fz = Fixed(5000, Eigen::Vector4d::Unit(0));
  in.kappa = Fixed(0.04, Eigen::Vector4d::Unit(1));
  in.alpha = Fixed(-0.06, Eigen::Vector4d::Unit(2));
  in.gamma = Fixed(0.02, Eigen::Vector4d::Unit(3));
  in.Vx = Fixed(16.7, Eigen::Vector4d::Zero());
  in.phit = Fixed(0.0, Eigen::Vector4d::Zero());
  in.pressure = Fixed(0.0, Eigen::Vector4d::Zero());
  const TireForces<Fixed> f = magic_formula(p, in);
  const TireForces<MfAD> g = magic_formula(p, mf_test_seed(5000, 0.04, -0.06, 0.02, 16.7));
  EXPECT_DOUBLE_EQ(f.Fy.value(), g.Fy.value());
  EXPECT_DOUBLE_EQ(f.Mz.value(), g.Mz.value());
  for (int j = 0; j < 4; ++j) {
    EXPECT_DOUBLE_EQ(f.Fy.derivatives()[j], g.Fy.derivatives()[j]) << j;
    EXPECT_DOUBLE_EQ(f.Mz.derivatives()[j], g.Mz.derivatives()[j]) << j;
    EXPECT_DOUBLE_EQ(f.Fx.derivatives()[j], g.Fx.derivatives()[j]) << j;
  }
}
