// The jobs of a front end, one call each: what `codyna info|linearize|simulate`, the Python
// module's Study.model_info / linearize / simulate and codyna-gui ask of the core. A front end
// turns its flags, keywords or widgets into a request (every option optional: what is not given
// keeps the model file's "analysis" and "solver" sections), makes one call, and shows the job it
// gets back. The job carries the messages a user must see (notes, warnings): the core prints
// nothing.
//
// Option names in messages follow the front end (OptionStyle): the CLI's "--trim-free", the
// Python module's "trim_free". Bad options throw std::invalid_argument naming the option; a bad
// model throws ModelError naming the file and the field; a failed search throws ConvergenceError.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "model/model.hpp"
#include "study/tools.hpp"
#include "study/workflow.hpp"

namespace codyna {

// A message a user must see, handed to the front end as it arises (the jobs also keep them).
struct StudyMessage {
  enum Kind { Note, Warning } kind = Note;
  std::string text;
};
using StudyMessages = std::function<void(const StudyMessage&)>;

enum class OptionStyle {
  Flag,     // --trim-free
  Keyword,  // trim_free
};
// "trim-free" written as the front end writes it
std::string option_name(OptionStyle style, const std::string& dashed);

// The plant selection and the study's signals for one run, over the model file's (each list given
// replaces the file's): inputs/outputs (actuator and sensor names, in order), disabled effects
// (effect names), references and disturbances (each a JSON object with the fields of the file's
// "references"/"disturbances" entries, or the step shorthand NAME=VALUE[@TIME]). Unknown names
// are refused naming the option and listing what exists; the signals go through the model file's
// reader, so their errors name the option and the field.
struct PlantRequest {
  std::optional<std::vector<std::string>> inputs, outputs, disabled_effects, references, disturbances;
};

// The operating point's choices shared by linearize and simulate. hold, initial and targets are
// NAME=VALUE texts (a name given again replaces its value), added to the file's lists.
struct PointRequest {
  std::optional<std::string> operating_point;  // initial | equilibrium | trim | steady | time=T
  std::optional<std::vector<std::string>> independent, trim_free, free_inputs;
  std::vector<std::string> hold, initial, targets;
  // operating point steady (StudySpec::steady): each given replaces the file's
  std::optional<std::string> steady_body;
  std::optional<double> speed, yaw_rate, radius, lateral_acceleration;
};

struct LinearizeRequest {
  OptionStyle style = OptionStyle::Flag;
  std::string model;  // the model file (messages, relative paths, outputs that must not replace it)
  std::string out;    // export folder ("" = compute only: the job exports nothing)
  PointRequest point;
  PlantRequest plant;
  std::optional<std::string> method, mat_version, name, controller;
  std::optional<double> discrete, trajectory, trajectory_step;
  bool closed_loop = false, lqr = false, lqr_controllable_part = false;
  std::optional<std::vector<double>> q_weights, r_weights;
  // false: no modal analysis and no unobservable modes (LinearizeJob::modes and unobservable
  // left empty), the rest as always: what each variant of a parameter study needs
  bool modes = true;
};

struct LinearizeJob {
  Model model;                                          // as the study sees it
  std::string name;                                     // the export's NAME
  std::string method;                                   // the Jacobians': "exact", "fd-forward", "fd-central"
  std::vector<std::string> notes, warnings;             // for the user, each in order
  // one operating point (not trajectory)
  StudyLinearization linearization;                     // op, continuous lin, exported system
  ModalAnalysis modes;                                  // of the exported system
  std::vector<HiddenMode> uncontrollable, unobservable;  // of the continuous plant
  std::vector<std::string> written;                     // files written, in order
  std::optional<StudyClosedLoop> closed_loop;           // with closed_loop
  std::vector<std::string> closed_loop_written;
  // along a trajectory (request.trajectory): one continuous system per output sample
  bool trajectory = false;
  std::vector<double> times;
  std::vector<LinearSystem> systems;
  std::string trajectory_controller;                    // "open loop" or the controller's description
  Eigen::VectorXd max_real, min_real;                   // the largest and smallest Re(eig A) per point
};

// The whole `codyna linearize`: the study's model, the operating point, A, B, C, D, modes,
// controllability, the closed loop when asked, and (when r.out is given) the exports, each
// checked before any work against replacing an input. `spec` is the model file as read.
LinearizeJob study_linearize_job(const LinearizeRequest& r, const ModelSpec& spec, const StudyMessages& tell = {});
// A parameter study's variant: `structure` is study_linearize_structure(r, nominal) of a nominal spec
// that differs from `spec` only in what `what` names (compile_numbers); the same job as above
// (study_model's overload: the tree, names and indices are not made again)
LinearizeJob study_linearize_job(const LinearizeRequest& r, const ModelSpec& spec, const Model& structure,
                                 NumbersChanged what, const StudyMessages& tell = {});
Model study_linearize_structure(const LinearizeRequest& r, const ModelSpec& spec);

struct SimulateRequest {
  OptionStyle style = OptionStyle::Flag;
  std::string model;        // the model file
  std::string out, csv;     // results (HDF5, CSV); "" = not written
  PointRequest point;
  PlantRequest plant;
  std::optional<std::string> controller;  // a .mat (relative to the working folder)
  bool lqr = false, lqr_controllable_part = false, compare_linear = false, open_loop = false;
  std::optional<double> linear_region;
  std::optional<std::vector<double>> q_weights, r_weights;
  std::optional<std::string> integrator;
  std::optional<double> t_end, rtol, atol, max_step, output_step, max_samples, divergence_bound;
  std::optional<double> alf_penalty;   // alf's settings (SolverSpec)
  std::optional<int> alf_iterations;
  std::optional<bool> alf_fixed_step;
  std::optional<bool> alf_extrapolate;
};

// The sample limit of a run shown live in a window, which keeps each run several times (plots, the
// signal list, runs kept for comparison); longer records are the command line's (codyna simulate,
// whose limit is SimulationOptions::max_samples).
constexpr double kShownRunMaxSamples = 1e6;

struct SimulateJob {
  Model model;
  std::vector<std::string> notes, warnings;  // each in order (the ready callback sees those before the run)
  StudySimulation setup;
  Eigen::VectorXd op_coordinates;            // the operating point's coordinates (Model::v_names), with a plant
  Eigen::VectorXd initial_coordinates;       // the run's start, when the study names an initial state
  SimulationResult result;
  LinearRegion region;                       // with a plant
  std::vector<Saturation> saturation;
  // with compare_linear: per Plant/Out, the largest |y - y_linear|, that as a percentage of the
  // output's excursion (its largest distance from its final value), and the first time the gap
  // passes 1 % of the excursion (-1: never)
  Eigen::VectorXd linear_gap, linear_gap_percent, linear_gap_from;
  // the linear closed-loop poles that are unstable (right half-plane, or outside the unit circle
  // for a sampled controller), in setup.linear_poles' order
  Eigen::VectorXcd unstable_poles;
  // over the run: the largest |u| of each Plant/In (in plant_inputs order), the total energy at the
  // first and last samples, and the largest constraint drift |phi|, |Jc v| (models with loops)
  Eigen::VectorXd max_abs_input;
  double energy_start = 0, energy_end = 0;
  double max_constraint_violation = 0, max_velocity_violation = 0;
  std::vector<std::string> written;
};

// The whole `codyna simulate`: the study's model, controller and plant, the run, the linear
// region, the saturation report and (when r.out/r.csv are given) the results written, each
// output checked before any work. `ready` (may be empty) sees the job once set up, before the run
// (what the CLI prints ahead of its progress bar). A run that fails is returned (result.completed
// false, result.failure) after its partial result is written; the caller decides what it means.
SimulateJob study_simulate_job(const SimulateRequest& r, const ModelSpec& spec, const SimulationCallbacks& cb = {},
                               const std::function<void(const SimulateJob&)>& ready = {},
                               const StudyMessages& tell = {});

// The export of a linearization already made (codyna-gui's Export after Linearize): NAME.mat and
// NAME.m of `system` in `dir` (relative to the model file's folder; "" = the study's export_dir),
// named and in the MAT version of `m`'s study as it is now, each output guarded as the linearize
// job's (never the model file, never a file codyna did not write).
ExportPaths study_export_linearization(const Model& m, const LinearSystem& system, const std::string& dir);

// What a simulate request sets up before a run, as study_simulate_job does (the request over the
// model file's study and solver sections, the model, the controller and the plant it is designed
// on), and, with `linearize` and no plant (open loop), the study's linearization about its
// operating point: what a job that runs the study several times (codyna freqresp) starts from.
// Refusals name the request's options, as study_simulate_job's.
struct SimulateSetup {
  Model model;
  StudySimulation setup;
  std::optional<StudyLinearization> linearization;  // `linearize` and no setup.plant
};
SimulateSetup study_simulate_setup(const SimulateRequest& r, const ModelSpec& spec, bool linearize,
                                   const std::atomic<bool>* cancel = nullptr);

// The Control view's analysis (codyna-gui's Analyse): the plant linearized about the study's
// operating point with its modes and its step and frequency responses on the grids the closed
// loop uses (the core's defaults from the plant's poles), and the study's closed loop
// (study_closed_loop) when the study has a controller. A closed loop that cannot be made is a
// note (the plant is still shown); a plant that cannot be linearized throws.
struct ControlRequest {
  OptionStyle style = OptionStyle::Flag;
  std::string model;  // the model file (messages, relative paths)
};

struct ControlJob {
  Model model;
  std::vector<std::string> notes, warnings;
  StudyLinearization plant;
  ModalAnalysis plant_modes;
  FrequencyResponse plant_frequency;
  StepResponse plant_step;
  std::optional<StudyClosedLoop> closed_loop;
  PoleCount closed_loop_count;  // of closed_loop->poles (count_stability)
  // A controller without states acts as u = u0 - K (x - x0): K (Plant/In x plant states) read
  // off the closed loop's effort rows, its rows named by the Plant/In actuators, its columns by
  // the plant's states. Empty otherwise.
  Eigen::MatrixXd gain;
  std::vector<std::string> gain_inputs, gain_states;
};
ControlJob study_control_job(const ControlRequest& r, const ModelSpec& spec, const StudyMessages& tell = {});

// The transmission zeros of one channel of the job's plant (closed = false) or closed loop: the
// Control view's pole-zero map of the pair it shows (the poles are the job's own modes).
Eigen::VectorXcd study_control_zeros(const ControlJob& job, bool closed, int input, int output);

// The model compiled as its file writes it, no study applied (validated, indexed, loops assembled,
// redundant rows found): what `codyna info` summarizes (Model has every name, index and unit) and
// what the co-simulation steps. ModelError names `file` and the field.
Model study_compile(const ModelSpec& spec, const std::string& file = "");
// What closing the loops moved, as text ("crank 2.0944 -> 2.09842 (moved by 0.00402 rad), ...";
// "" when nothing moved).
std::string study_assembly_moves_text(const Model& m);

}  // namespace codyna
