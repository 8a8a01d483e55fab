// Results files: a SimulationResult (simulation/result.hpp) written to HDF5 (for
// h5py, MATLAB and GNU Octave, and for the GUI to reopen) or to CSV, and read
// back from HDF5. Uses the HDF5 C library.
//
// HDF5 layout (N samples; every path is from the root):
//   /time                            double (N)
//   /q /v /u /y /xc                  double (N x nq), (N x nv), (N x nu), (N x ny), (N x nxc)
//   /y_linear                        double (N x ny), only when y_linear has columns (a linear run)
//   /y_reference                     double (N x ny), only when the run had references r(t)
//   /u_disturbance                   double (N x nu), only when the run had disturbances d(t)
//   /s, /names/effect_states         double (N x ns) and its names, only when the model has effect
//                                    states (a tire's contact deflections: transient slip); CSV:
//                                    their columns last
//   /energy/kinetic                  double (N)
//   /energy/potential                double (N)
//   /constraints/position_violation  double (N)   (SimulationResult::constraint_violation)
//   /constraints/velocity_violation  double (N)
//   /names/q /names/v /names/inputs /names/outputs /names/controller_states
//   /units/inputs /units/outputs     string lists (n), one entry per column, in column order
//   /solver       group; attributes integrator (string), rtol atol max_step wall_time (double),
//                 steps rhs_evals jac_evals error_test_failures nonlinear_iterations
//                 nonlinear_failures projections restarts (int64)
//   /status       group; attributes completed cancelled (int32, 0 or 1), failure (string, "" if none)
//   /provenance   group; attributes model_name model_file controller codyna_version settings_json (string)
//   /             attribute format_version (int32, 1) marks a codyna results file
//
// Matrices are stored in HDF5's native row-major order, one row per sample:
// h5py reads f['q'] with shape (N, nq). MATLAB (h5read) and Octave (load) see
// the transpose, nq x N (one column per sample), and vectors as rows or columns.
// A matrix with no columns (e.g. xc without a controller) is stored as (N, 0)
// and read back as N x 0; a partial result may have N = 0.
//
// Strings. The string lists are fixed-length, NUL-padded strings, because
// Octave 7's load() aborts on a file that holds any variable-length string
// dataset. Their character set is tagged ASCII although they carry UTF-8 bytes:
// HDF5 1.10 cannot convert a UTF-8-tagged string to the ASCII string that
// Octave reads into, so a UTF-8 tag would make load() fail too. In h5py they
// are numpy 'S' arrays of UTF-8 bytes (f['names/q'].asstr('utf-8')[()] gives
// str; a bare asstr() follows the ASCII tag and fails on non-ASCII text).
// Attributes are variable-length UTF-8 strings (h5py: str, MATLAB: h5readatt),
// since Octave ignores attributes anyway.
//
// What GNU Octave 7.3 can read (it has no h5read/h5info/h5readatt; checked by
// tests/peers/read_results.m): s = load('run.h5') gives every dataset: s.time
// (1 x N), s.q (nq x N), ..., s.xc (nxc x N, [](0xN) without a controller),
// s.energy.kinetic, s.constraints.position_violation, ..., and each string
// list as a blank-padded char matrix, one row per name (s.names.q; use
// cellstr()). It cannot read attributes: s.solver, s.status and s.provenance
// are empty structs, so solver statistics, completion status, the failure text
// and provenance are visible only to h5py, MATLAB or read_results_hdf5().
//
// The HDF5 functions use the serial (not thread-safe) HDF5 library: do not run
// them concurrently with each other or with other HDF5 use in the process.
#pragma once

#include <string>

#include "simulation/result.hpp"

namespace codyna {

// Writes `r` to `path` in the layout above. Atomic: the file is written as a
// temporary file in the same directory (io/atomic_file.hpp) and renamed over
// `path`; on failure nothing is left and an existing file is untouched. A
// partial result (completed == false, failure text set) is written the same
// way. Throws std::runtime_error naming `path` and the reason: a directory that
// is missing or not writable, an HDF5 failure, or an inconsistent result
// (a series or matrix whose length is not N, a name list whose size is not the
// number of columns, unit lists neither empty nor one per column, y_linear or
// y_reference with other than ny columns, u_disturbance with other than nu).
void write_results_hdf5(const SimulationResult& r, const std::string& path);

// Writes `r` to `path` as CSV: the header row
//   t,<q names>,<v names>,<input names>,<output names>,<controller state names>,
//   kinetic_energy,potential_energy,constraint_violation[,<output name>_linear...]
//   [,<output name>_reference...][,<input name>_disturbance...]
// (one line), then one row per sample. Numbers are printed like "%.17g" in the
// C locale whatever the current locale is (they read back to the same doubles;
// "nan", "inf", "-inf" for non-finite values); lines end in "\n"; a name that
// holds a comma, a quote or a line break is quoted as in RFC 4180. The velocity
// violation, units, solver statistics, status and provenance are in the HDF5
// file only. Atomic and throwing like write_results_hdf5.
void write_results_csv(const SimulationResult& r, const std::string& path);

// Both at once (csv_path may be ""): both files are written completely before either
// replaces an old one, so an interrupted run leaves the old pair or the new pair
// (only a failure between the two renames could mix them).
void write_results(const SimulationResult& r, const std::string& hdf5_path, const std::string& csv_path);

// Reads what write_results_hdf5 wrote; the result equals the one written
// (bit for bit), except that a y_linear, y_reference or u_disturbance without columns comes back 0 x 0 and
// any other matrix without columns comes back N x 0. Throws std::runtime_error naming `path` and
// the reason (no such file, not an HDF5 file, not a codyna results file, a
// missing or malformed dataset or attribute, inconsistent sizes).
SimulationResult read_results_hdf5(const std::string& path);

}  // namespace codyna
