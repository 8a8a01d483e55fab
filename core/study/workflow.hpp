// The workflow of one study (model/study_spec.hpp), one function per step:
//
//   study_model            the model as this study sees it: disabled effects left
//                          out, held coordinates set, loops re-assembled
//   study_initial_state    where a run starts (the study's `initial`), apart from the
//                          operating point
//   study_operating_point  initial / equilibrium / trim / time=T
//   study_linearize        A, B, C, D there (exact or finite differences, ZOH on request)
//   study_export           NAME.mat + NAME.m
//   study_simulation       the controller and plant a closed-loop run needs, and
//   study_simulate         the run itself (callbacks for progress, samples, cancel)
//
// These are the steps; the front ends (the CLI, codyna-gui, Python) do not call them one by
// one: each runs a job (study/jobs.hpp), which applies its request to the model file's
// "analysis" section and calls these in order. The steps live in workflow.cpp (model, operating
// point, linearization, export), workflow_handling.cpp (the handling numbers and the text about a
// steady motion) and workflow_simulation.cpp (the closed-loop run). Bad choices
// throw ModelError naming the file and the field ("/analysis/operating_point"), which a job
// says of the flag or keyword when its request gave the value, or std::invalid_argument.
#pragma once

#include <atomic>
#include <memory>
#include <stdexcept>
#include <string>

#include "analysis/closed_loop_linear.hpp"
#include "analysis/handling.hpp"
#include "analysis/linearize.hpp"
#include "analysis/modal.hpp"
#include "analysis/operating_point.hpp"
#include "control/controllability.hpp"
#include "io/mat_export.hpp"
#include "model/compile.hpp"
#include "model/model.hpp"
#include "simulation/controller.hpp"
#include "simulation/simulator.hpp"

namespace codyna {

// `file` is where the spec was read (for messages and relative paths); may be "".
// A controller file saved with its export's codyna_study brings its operating point along:
// see adopt_controller_study, which study_model applies first.
Model study_model(const ModelSpec& spec, const std::string& file = "");

// The same from `structure`, study_model_structure of a spec that differs from `spec` only in what
// `what` names (a parameter study's variants reuse the nominal model's tree, names and indices:
// model/compile.hpp's compile_numbers); the same model as study_model(spec, file).
Model study_model(const ModelSpec& spec, const std::string& file, const Model& structure, NumbersChanged what);
// compile_structure of the spec as study_model compiles it, for the overload above (without its spec)
Model study_model_structure(const ModelSpec& spec, const std::string& file = "");

// When the study's controller is a .mat that holds codyna_study (what NAME.m's export
// puts in the workspace; save it with K), that study's operating point, coordinates set,
// independent coordinates and disabled effects replace the spec's, and a note says so
// (spec.notes): the offsets follow the controller without the user repeating flags.
// Returns true when it did.
bool adopt_controller_study(ModelSpec& spec, const std::string& file);

// The simulation's initial state: the model's state (held coordinates `set` included) with the
// study's `initial` coordinates and rates set on it and the loops closed with those held
// (ModelError at /analysis/initial/NAME for an unknown name, at /analysis/initial when the
// loops cannot hold them). `given` is false when the study names none (q, v are the model's).
// The operating point does not depend on it: it is searched from the model's state.
struct StudyInitialState {
  Eigen::VectorXd q, v;
  bool given = false;
};
StudyInitialState study_initial_state(const Model& model);

// The coordinates (Model::v_names) of a configuration q: the joints' values, a ball's or free
// joint's rotation vector (the log of its quaternion, |r| <= pi) and a free joint's position.
// What `info`, --hold and --initial name; the stored q keeps quaternions.
Eigen::VectorXd study_coordinates(const Model& model, const Eigen::VectorXd& q);

// The operating point the study asks for (`which` overrides study.operating_point
// when not empty). An equilibrium or trim search ends with a verdict: one that does not
// converge (residual accelerations of 1e-8 or more, outputs off their targets, inputs held
// at their limits) throws ConvergenceError (model/errors.hpp) naming the residual, the
// unknowns and what to free; nothing is linearized, exported or simulated about it.
//
// `cancel` (may be null): a time=T pre-run stops at its next step once *cancel is true and
// StudyCancelled is thrown (the searches are short and not interrupted).
OperatingPoint study_operating_point(const Model& model, const std::string& which = "",
                                     const std::atomic<bool>* cancel = nullptr);

// What a study step throws when its caller cancelled it (a front end's Cancel): not an error of
// the model, nothing was produced.
struct StudyCancelled : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct StudyLinearization {
  OperatingPoint op;
  Linearization lin;    // continuous
  LinearSystem system;  // what is exported: lin.system, or its ZOH form when study.discrete > 0
  // at a steady motion whose study names the steer input and the yaw-rate output (StudySpec::handling)
  std::optional<HandlingNumbers> handling;
};

// What the operating point's motion is, for the user: the steady body's speed and turn, the frame
// the state moves with, the coordinates that advance (empty when the point is not a motion).
std::string study_motion_text(const Model& model, const OperatingPoint& op);
// The handling numbers as the command line prints them (one per line, with units).
std::string study_handling_text(const HandlingNumbers& h);

StudyLinearization study_linearize(const Model& model);

// The plant's export name: study.export_name, or the model name as a MATLAB identifier.
std::string study_export_name(const Model& model);

// `dir` empty: study.export_dir (relative to the model file's folder); created if missing.
ExportPaths study_export(const Model& model, const LinearSystem& system, const std::string& dir = "");

// A path of the study (controller file, export folder) resolved against the model file's folder.
std::string study_path(const Model& model, const std::string& path);

struct StudySimulation {
  std::shared_ptr<const LinearPlant> plant;      // null when nothing needs one
  std::shared_ptr<const Controller> controller;  // null: open loop (actuators at u0)
  SimulationOptions options;
  std::string controller_source;                 // "the model file's pid controller", "lqr", "K.mat", "none"
  Eigen::MatrixXd lqr_gain;                      // the gain designed, when the source is "lqr"
  Eigen::VectorXcd lqr_poles;                    // eig(A - B lqr_gain), when the source is "lqr"
  std::vector<HiddenMode> uncontrollable;        // lqr_controllable_part: the modes left as they are
  std::vector<std::string> notes;                // what a front end should tell the user
  // where the run starts (StudySpec::start): "model", "study initial" (the model's state with the
  // study's initial coordinates), or the operating point's kind ("equilibrium", "trim", ...), with
  // " + study initial" when coordinates are set on it
  std::string start = "model";
  std::string start_point;  // the operating point's kind when the run starts at it ("" otherwise)
  // a linear controller (state feedback, LQR, LTI; not PID, not open loop): the poles of the
  // linear closed loop about the operating point (close_loop of analysis/closed_loop_linear.hpp,
  // saturation left out), sorted by real part; `linear_unstable` when one has a real part
  // above 1e-9 max(1, |Acl|) (continuous) or a magnitude above 1 + 1e-9 (a sampled controller).
  // Empty when there is no such controller. The run is not refused for it.
  Eigen::VectorXcd linear_poles;
  bool linear_discrete = false;
  double linear_tolerance = 1e-9;  // stability_tolerance of the closed loop's A (analysis/stability.hpp)
  bool linear_unstable = false;    // a pole classify_pole calls unstable
};

// The configuration the 3-D view draws for a linear mode: the operating point q_op moved
// along Re(shape e^{i phase}) on the position states (named as the linearization names
// them: the coordinates of Model::v_names; a ball's or free joint's "J.rx".."J.rz" and a free
// joint's "J.x".."J.z" are tangent deviations in the joint's frame), scaled so that the largest of them
// swings by `amplitude` (rad or m), mapped onto the manifold (q_op (+) dv: quaternions
// stay unit), closed loops re-assembled. States that name no coordinate are skipped.
Eigen::VectorXd study_mode_pose(const Model& model, const Eigen::VectorXd& q_op,
                                const std::vector<std::string>& state_names, const Eigen::VectorXcd& shape,
                                double phase, double amplitude = 0.3);

// Controller and linear plant of the run (linearizing once if anything needs it).
// `cancel` as in study_operating_point (the plant's operating point may be a time=T pre-run).
StudySimulation study_simulation(const Model& model, const std::atomic<bool>* cancel = nullptr);

SimulationResult study_simulate(const Model& model, const StudySimulation& setup, const SimulationCallbacks& cb = {});

// How far a closed-loop run went from the operating point its linear parts are about: the
// distance is |coordinate - its value there| (the tangent difference; rad or m) on the
// independent coordinates the linear dynamics depend on (a nonzero column of A: a cart's
// position or a free body's position and heading, on which nothing depends, are not measured),
// against study.linear_region. `left_at` is the first sample beyond it (-1: never); `settled`
// says the run ends at rest (every rate below 1e-4 of its largest in the run, or 1e-9), so a
// final distance beyond the bound is a settling elsewhere. Empty (`measured` empty) without a plant.
struct LinearRegion {
  double bound = 0;
  std::vector<std::string> measured;  // the coordinates measured
  double left_at = -1;
  std::string left_on;                // the coordinate first beyond the bound
  double largest = 0;                 // the largest distance in the run, and where
  std::string largest_on;
  double final_distance = 0;
  std::string final_on;
  bool settled = false;
};
LinearRegion study_linear_region(const Model& model, const StudySimulation& setup, const SimulationResult& r);

// The linear closed loop of the study's plant and controller (analysis/closed_loop_linear.hpp):
// the plant and controller study_simulation makes (same operating point, same Nbar), the
// study's disturbance actuators as extra inputs, the poles, and the step and frequency
// responses on the grids of study.closed_loop (automatic where 0). A state feedback whose
// study names no reference gets Nbar for the first min(nu, ny) Plant/Out outputs (a note says so).
struct StudyClosedLoop {
  StudySimulation setup;
  ClosedLoopLinear loop;
  ModalAnalysis poles;
  StepResponse step;
  FrequencyResponse frequency;
  std::vector<std::string> notes;
};
StudyClosedLoop study_closed_loop(const Model& model);

// Writes DIR/NAME_cl.mat + NAME_cl.m (Acl, Bcl, Ccl, Dcl with names; io/mat_export.hpp) and the
// curves DIR/NAME_cl_step.csv, DIR/NAME_cl_freq.csv; NAME is study_export_name. Returns the paths.
std::vector<std::string> study_export_closed_loop(const Model& model, const StudyClosedLoop& cl, const std::string& dir = "");

}  // namespace codyna
