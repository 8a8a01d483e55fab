// study_control_job (study/jobs.hpp): the Control view's plant and closed loop in one call.
#include <Eigen/Core>
#include <exception>

#include "analysis/closed_loop_linear.hpp"
#include "analysis/modal.hpp"
#include "analysis/zeros.hpp"
#include "io/model_file.hpp"
#include "study/jobs.hpp"

namespace codyna {

ControlJob study_control_job(const ControlRequest& r, const ModelSpec& spec, const StudyMessages& tell) {
  ControlJob job;
  auto note = [&](const std::string& s) {
    job.notes.push_back(s);
    if (tell) tell({StudyMessage::Note, s});
  };
  job.model = study_model(spec, r.model);
  const Model& m = job.model;
  job.plant = study_linearize(m);
  const LinearSystem& p = job.plant.system;
  job.plant_modes = modal_analysis(p);
  const auto [w_lo, w_hi] = default_frequency_range(job.plant_modes, p.Ts);
  job.plant_frequency = frequency_response(p, log_grid(w_lo, w_hi, 400));
  job.plant_step = step_response(p, default_step_time(job.plant_modes), 500);
  try {
    job.closed_loop = study_closed_loop(m);
  } catch (const std::exception& e) {
    note(std::string("no closed loop: ") + e.what());
    return job;
  }
  for (const std::string& n : job.closed_loop->notes) note(n);
  job.closed_loop_count = count_stability(job.closed_loop->poles);
  const ClosedLoopLinear& L = job.closed_loop->loop;
  if (L.nxc == 0 && L.nu > 0 && L.nx > 0 && L.nu == p.nu() && L.nx == p.nx()) {
    // the loop's effort rows are u - u0 = -K (x - x0) (closed_loop_linear.hpp)
    job.gain = -L.system.C.block(L.ny, 0, L.nu, L.nx);
    job.gain_inputs = p.input_names;
    job.gain_states = p.state_names;
  }
  return job;
}

Eigen::VectorXcd study_control_zeros(const ControlJob& job, bool closed, int input, int output) {
  const LinearSystem* s = closed ? (job.closed_loop ? &job.closed_loop->loop.system : nullptr) : &job.plant.system;
  if (!s || input < 0 || output < 0 || input >= s->nu() || output >= s->ny()) return {};
  return study_zeros(*s, input, output).zeros;
}

}  // namespace codyna
