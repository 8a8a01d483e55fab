// MAT export and import: the plant goes out to MATLAB/GNU Octave as
// DIR/NAME.mat + DIR/NAME.m, a controller comes back as a .mat of plain matrices
// (ARCHITECTURE.md, "Export contract"). Uses libmatio.
//
// NAME.mat holds
//   A B C D                      double, true sizes (nx x 0 B, 0 x nx C, ... when nu or ny is 0)
//   x0 u0 y0 xdot0               double column vectors (operating point)
//   Ts                           double scalar (0 = continuous)
//   state_names input_names output_names  cell (n x 1) of char rows
//   state_units input_units output_units  cell (n x 1) of char rows
//   info                         struct: model_name, model_file, operating_point,
//                                method, time (double), codyna_version, name
// and, in v7.3 files only, the six lists again as blank-padded char matrices
// (state_names_char, ...), because Octave cannot read the cell arrays of a v7.3
// file; NAME.m falls back to cellstr() of those (Octave also reads the empty
// matrices of a v7.3 file as their size vectors; a v7.3 NAME.m resets those from
// the sizes it was written with). Text is stored as UTF-16 (what
// MATLAB writes; Octave converts it); scipy.io.loadmat needs uint16_codec='utf-16'
// for non-ASCII text.
//
// NAME.m is a plain script for MATLAB and Octave: it loads NAME.mat from its own
// folder, loads Octave's control package when there is one, defines
// plant_inputs / plant_outputs, builds the named model `sys = ss(...)` when ss()
// exists, and prints a short summary.
#pragma once

#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "analysis/closed_loop_linear.hpp"
#include "analysis/linear_system.hpp"
#include "analysis/modal.hpp"

namespace codyna {

enum class MatVersion { V5, V73 };

struct ExportPaths {
  std::string mat_file, m_file;
};

// Writes DIR/NAME.mat and DIR/NAME.m, each atomically (temporary file + rename),
// the .mat first. NAME must already be what matlab_identifier(NAME) returns.
// Empty offsets count as zeros, an empty D as zeros(ny, nu), empty name lists
// as x1.., u1.., y1.., empty unit lists as ''. Throws std::runtime_error naming
// the file and the reason, or std::invalid_argument when a path may not be
// written (io/output_guard.hpp: it is the model file, or a file codyna did not
// write) (bad NAME, sizes that do not fit, NaN/Inf entries, a
// directory that is missing or not writable, a failed write); nothing is then
// left behind, and existing files of that name are untouched. (Both files are
// complete before the two renames; only a failure of the second rename, after
// the first succeeded, would leave a new NAME.mat beside an old NAME.m.)
ExportPaths export_plant(const LinearSystem& sys, const std::string& dir, const std::string& name,
                         MatVersion v = MatVersion::V5);

// Linearizations along a trajectory (same state order, one per time): DIR/NAME.mat
// (MAT v5) holds A (nx x nx x N), B, C, D likewise, x0, u0, y0, xdot0 (one column per
// point), t (N x 1), Ts = 0, the name and unit lists and info; DIR/NAME.m loads it and
// defines plant_at(k), the named ss model at point k, when ss() exists. Atomic.
ExportPaths export_trajectory(const std::vector<LinearSystem>& systems, const std::vector<double>& times,
                              const std::string& dir, const std::string& name);

// The linear closed loop (analysis/closed_loop_linear.hpp) of a plant NAME: DIR/NAME.mat (MAT v5;
// NAME is the plant's export name + "_cl") holds Acl, Bcl, Ccl, Dcl, Ts_cl, the lists
// state_names_cl, input_names_cl, output_names_cl (and *_units_cl), the offsets x0_cl, u0_cl
// (the inputs' base values: y0, then the disturbed actuators' nominal values), y0_cl ([y0; u0]),
// poles_cl (n x 4: real, imaginary part, natural frequency rad/s, damping), the grids t_step
// and w_freq of the curves, and info_cl (model, operating point, controller, codyna version);
// DIR/NAME.m loads it and builds the named model sys_cl when ss() exists. Atomic, guarded as
// export_plant is.
ExportPaths export_closed_loop(const ClosedLoopLinear& cl, const ModalAnalysis& poles, const std::vector<double>& t_step,
                               const std::vector<double>& w_freq, const std::string& dir, const std::string& name);

// A valid MATLAB (and Octave) identifier that is also safe as a script name:
// characters other than [A-Za-z0-9_] become '_' ("cart-pendulum 2" ->
// "cart_pendulum_2"); not starting with a letter -> prefix "m_"; at most 63
// characters; keywords, the variables NAME.m defines and the functions it calls
// get the suffix "_plant" ("end" -> "end_plant", "A" -> "A_plant"); "" -> "plant".
std::string matlab_identifier(const std::string& s);

// Text as MATLAB stores a char array: UTF-16 code units (invalid UTF-8 bytes become U+FFFD); what
// every MAT file codyna writes holds, the plant's and the sweep's alike
std::u16string mat_utf16(const std::string& s);

// The text of NAME.m for `sys` (what export_plant writes).
std::string plant_script(const LinearSystem& sys, const std::string& name, MatVersion v);

struct SkippedVariable {
  std::string name;
  std::string reason;  // "complex", "struct", "cell" (not all char rows), "sparse (store full())", "3-D array", ...
};

struct MatVariables {
  std::map<std::string, Eigen::MatrixXd> matrices;              // every real numeric 2-D variable, as double
  std::map<std::string, std::vector<std::string>> strings;      // char rows and cell arrays of them, UTF-8
  std::vector<SkippedVariable> skipped;                         // everything else
};

// Reads every real numeric variable (double, single, integer or logical,
// converted to double) of a MAT file (v4, v5/v7, v7.3), and its text: a char
// row -> one string, a char matrix -> one string per row (trailing blanks
// removed, as cellstr does), a cell array of char rows -> its strings in
// column-major order (names that travel with a controller). Complex, sparse,
// N-D, struct and other variables are listed in `skipped`. Throws
// std::runtime_error naming the file and the problem: missing or unreadable
// file, not a MAT file (Octave's text or binary format: "save with -v7 or
// -mat7-binary"), a variable with NaN or Inf entries (named).
MatVariables read_mat_file(const std::string& path);

}  // namespace codyna
