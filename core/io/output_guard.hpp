// Output paths never replace a user's files. Before codyna writes an output it
// checks the path: an output that is the same file as an input (same device
// and inode, so through symbolic and hard links too), or an existing file that
// codyna did not write as an output of the same kind (told by its first bytes),
// or anything that is not a regular file (a directory, a FIFO, a device) is
// refused with std::invalid_argument naming the path and the reason. Nothing
// is written then. The writers in io/ call this themselves (their inputs are
// the model file recorded in what they write); front ends call it before a run
// so that a bad output path fails before the work, not after.
#pragma once

#include <string>
#include <vector>

namespace codyna {

enum class OutputKind {
  ResultsHdf5,  // simulation results (write_results_hdf5)
  ResultsCsv,   // simulation results as CSV (write_results_csv)
  PlantMat,     // NAME.mat of an export (MAT v5 or v7.3)
  PlantScript,  // NAME.m of an export
  CurvesCsv,    // step or frequency responses of a closed loop (io/curves_file.hpp)
  Mjcf,         // a model exported as MJCF (io/export_mjcf.hpp; its first line says codyna wrote it)
  SweepCsv,     // a parameter study's table (io/sweep_files.hpp; it begins "variant,status")
  TireCsv,      // a tire test rig's table (study/tire_job.hpp; it begins "Fx,Fy,Fz,")
  FrequencyResponseCsv,  // a nonlinear plant's frequency response (study/freqresp_job.hpp; it begins "w_rad_s,")
  KcCsv,        // a suspension K&C rig's table (study/kc_job.hpp; it begins "sweep,wheel,travel_m,")
};

const char* describe(OutputKind k);  // "an HDF5 results file", ...

// Throws std::invalid_argument when `path` may not be written (see above). `inputs` are
// files the run reads (empty strings are ignored; files that do not exist are ignored).
void guard_output(const std::string& path, OutputKind kind, const std::vector<std::string>& inputs);

// true when `path` exists and is the same file as `other` (device and inode)
bool same_file(const std::string& path, const std::string& other);

}  // namespace codyna
