// simulate(): the closed-loop nonlinear simulation of a model, with the
// controller in the loop, recorded at output times; optionally the linear
// closed loop (A, B, C, D with the same controller) from the same initial
// offset beside it.
//
// Ready for a GUI worker thread: progress and sample callbacks receive copies
// (never the integrator's data), cancellation is cooperative through an
// atomic flag, and a cancelled or failed run returns its partial result with
// the reason (SimulationResult::cancelled / failure).
#pragma once

#include <atomic>
#include <functional>
#include <optional>

#include "analysis/linearize.hpp"
#include "simulation/controller.hpp"
#include "simulation/integrator.hpp"
#include "simulation/result.hpp"

namespace codyna {

// A second controller in the same run, beside the one simulate() is given: sampled (its
// sample_time() > 0, zero-order hold), reading sensors and setting actuators by their indices in
// the model rather than through Plant/Out and Plant/In (a driver that steers and holds the speed
// while a yaw-moment controller acts on the brakes through Plant/In). It reads outputs only (no
// rates, no state feedback); its actuators must not be Plant/In inputs when there is a first
// controller. Its state is its own (not in SimulationResult::xc); its values are in u.
struct SampledBeside {
  const Controller* controller = nullptr;  // none: nothing beside
  std::vector<int> sensors;                // Model::sensors, in the order its outputs() read them
  std::vector<int> actuators;              // Model::actuators, in the order its output() gives them
};

struct SimulationOptions {
  IntegratorSettings integrator;
  double t0 = 0.0, t_end = 5.0, output_step = 0.01;
  Eigen::VectorXd q0, v0;              // initial state; empty = the model's (assembled) initial state
  Eigen::VectorXd s0;                  // initial effect states (Model::ns); empty = at rest at (q0, v0)
                                       // (effect_states_steady: a tire's steady slips)
  double projection_tolerance = 1e-9;  // closed loops: at every stop (output time, controller sample)
                                       // project when max |phi| (or max |Jc v| / max(1, |v|)) exceeds it
  Baumgarte stabilization{};           // optional, on the acceleration-level constraints
  bool compare_linear = false;         // also run the linear closed loop (needs a plant)
  double max_samples = 1e7;            // a run recording more output samples is refused before it starts
  double divergence_bound = 1e8;
  // r(t) for the Plant/Out outputs (ny values), for every controller type (docs/simulation.md:
  // PID acts on r - y, state feedback adds Nbar (r - y0), LTI sees y - r); empty: none
  std::function<Eigen::VectorXd(double)> reference;       // a state entry (q, v, controller) past this, or not finite, ends the run
  // d(t) added to the actuators' nominal values, one entry per actuator (Model::actuators; zero
  // for those not disturbed); the linear comparison adds LinearPlant::Bw/Dw times the entries of
  // LinearPlant::disturbance_actuators; empty: none
  std::function<Eigen::VectorXd(double)> disturbance;
  // motion inputs (Model::motions) moved by a disturbance: its rate and acceleration (one entry per
  // actuator, like `disturbance`; right-continuous), and the times where a rate jumps (a ramp's
  // start, a table's knots), where the run stops and applies the impulse (prescribed_velocity_jump)
  std::function<Eigen::VectorXd(double)> disturbance_rate, disturbance_acceleration;
  std::vector<double> rate_jumps;
  SampledBeside beside;
};

// What a sample callback gets: copies, safe to hand to another thread.
struct Snapshot {
  double t = 0;
  Eigen::VectorXd q, v, u, y;
};

struct SimulationCallbacks {
  std::function<void(double t, double t_end)> progress;
  std::function<void(const Snapshot&)> on_sample;
  // a front end's Cancel: seen inside the integrator's steps (ClosedLoopSystem::set_cancel), the
  // run returns at once with SimulationResult::cancelled
  const std::atomic<bool>* cancel = nullptr;
  // the caller's own stop (e.g. set by on_sample when a car has rolled over), seen the same way and
  // ending the run the same way (cancelled); kept apart from `cancel` so that the caller can tell
  // the user's Cancel from its own reason
  const std::atomic<bool>* stop = nullptr;
};

// The linearized plant a controller was designed on (state order, offsets).
struct LinearPlant {
  OperatingPoint op;
  Linearization lin;
  // disturbance inputs (actuators that are not Plant/In): their columns of B and D in the
  // same linearization, in the order of disturbance_actuators (indices into Model::actuators)
  std::vector<int> disturbance_actuators;
  Eigen::MatrixXd Bw, Dw;  // nx x nd, ny x nd
  // disturbed motion inputs: the linear state is xi = x - Fw_rate w' - Fw w (Linearization::motion_shift);
  // the controller sees x. Empty or zero without them
  Eigen::MatrixXd Fw, Fw_rate;  // nx x nd
};

SimulationResult simulate(const Model& model, const Controller* controller, const LinearPlant* plant,
                          const SimulationOptions& options, const SimulationCallbacks& callbacks = {});

// A run that starts at an operating point with every actuator held at its value there (a steady
// motion's steer and drive, which the search solved): the model with those nominal inputs, and
// options' initial state set to the point's (its effect states at rest there, as always).
Model held_at(const Model& model, const OperatingPoint& op, SimulationOptions& options);

// Actuators that sat at a limit during a run: how long (summed over the output samples
// at the limit, each counting one output interval) and from when. Empty when none did.
struct Saturation {
  std::string actuator;
  double at_max = 0, at_min = 0;  // seconds
  double first = 0;               // time of the first sample at a limit
};
std::vector<Saturation> saturation_report(const Model& model, const SimulationResult& result);
// "U at its limit from t = 0.12 s: 0.3 s at max, 0 s at min" (codyna simulate and the GUI say it so)
std::string saturation_text(const Saturation& s);

}  // namespace codyna
