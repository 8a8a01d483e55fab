// The records of a parameter study (`codyna sweep`, run by study/sweep.hpp): the varied fields,
// the plan of their values, each variant's figures and the study's, as the sweep's files hold
// them (io/sweep_files.hpp writes the HDF5, CSV, MAT files and the journal).
#pragma once

#include <complex>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Dense>

namespace codyna {

// One --vary, parsed.
struct SweepVary {
  std::string field;               // a JSON pointer into the model file
  std::string spec;                // as given
  enum Kind { Grid, Normal, Uniform } kind = Grid;
  std::vector<double> values;      // Grid: the values (linspace or the list)
  double a = 0, b = 0;             // Normal: mu, sigma; Uniform: a, b
  double nominal = 0;              // the model file's value
};

// The variants' values, a function of the specs, the seed and the index only.
struct SweepPlan {
  std::vector<SweepVary> vary;
  bool random = false;
  std::uint64_t seed = 0;
  long long count = 0;
  std::vector<double> values(long long i) const;  // one per --vary
};

enum class SweepStatus : int {
  Ok = 0,
  ModelError = 1,       // the variant's model is refused (ModelError)
  NotConverged = 2,     // its operating point search did not converge (ConvergenceError)
  Refused = 3,          // a choice cannot be applied to it (std::invalid_argument: an LQR not stabilizable)
  Failed = 4,           // any other failure
  SizeDiffers = 5,      // its A, B, C, D are not the nominal's sizes
};
const char* to_string(SweepStatus s);

struct SweepVariant {
  std::vector<double> values;                 // one per --vary
  SweepStatus status = SweepStatus::Failed;
  std::string reason;                         // "" when Ok
  Eigen::MatrixXd A, B, C, D, K;              // continuous plant; K only when redesigned
  Eigen::VectorXcd open_poles, closed_poles;  // sorted by real part, then imaginary part
  double open_max_real = 0, closed_max_real = 0;
  bool stable = false;                        // closed loop (no closed loop: open loop), asymptotically
  bool open_stable = false;                   // the open loop, asymptotically (analysis/stability.hpp)
  int uncontrollable = 0;                     // modes the Plant/In inputs cannot move
  std::string uncontrollable_text;            // study_describe_modes of them
  // simulate: the run's status (-1 not run, 0 reached t_end, 1 the run failed, 2 it could not be
  // set up), its reason, the time reached, the largest |u| of each Plant/In and the final error
  // (the largest |y - target| over Plant/Out at the last sample: the reference there, or y0)
  int sim_status = -1;
  std::string sim_reason;
  double sim_t_end = 0, final_error = 0;
  Eigen::VectorXd peak_input;
  // simulate, per Plant/Out (docs/parameter-studies.md, "Figures of merit"): e(t) = y(t) - target,
  // E = max |e| over the run; overshoot = 100 max(0, max(-s e)) / E in % (s the sign of e where
  // |e| = E), settling time = when |e| enters the band 0.02 E for good (linear between samples;
  // NaN when the last sample is outside it); per Plant/In: the seconds spent at a limit (min or
  // max, summed over the output intervals, as simulate's saturation report counts them)
  Eigen::VectorXd overshoot, settling_time, saturation_time;
};

struct SweepJob {
  std::string model_name, model_file;
  SweepPlan plan;
  std::vector<std::string> state_names, input_names, output_names;
  std::string operating_point, method;
  bool closed_loop = false;                   // a state feedback closes the loop
  std::string controller;                     // what the closed loop is ("the model file's lqr controller, K fixed")
  bool redesigned = false;
  bool simulated = false;
  Eigen::MatrixXd K;                          // the nominal gain (nu x nx), when closed_loop
  Eigen::VectorXcd nominal_closed_poles, nominal_open_poles;
  std::vector<SweepVariant> variants;
  std::vector<std::string> notes, warnings;
  std::vector<std::string> written;
  long long resumed = 0;                      // variants read back from the journal
  long long shard_index = 0, shard_count = 0;  // a shard's (shard_count 0: the whole study)
  std::string journal;                        // a shard's journal, with journal_in_memory
  bool in_shard(long long i) const { return shard_count == 0 || i % shard_count == shard_index; }
  // summary
  long long failed = 0, stable = 0;
  long long worst = -1;                       // the completed variant with the largest max real part
  long long sim_completed = 0;                // simulate: runs that reached t_end
  long long largest_input = -1;               // simulate: the run with the largest peak |u|
};

// The counter-based mixing function of the study's random numbers and of its journal's hash
// (splitmix64)
std::uint64_t sweep_mix64(std::uint64_t z);

}  // namespace codyna
