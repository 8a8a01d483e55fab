// codyna_plant: the nonlinear codyna plant stepped from GNU Octave (and, built
// with MATLAB's mex, from MATLAB): co-simulation in the spirit of the paper's
// MEX S-function. Octave holds the controller, codyna integrates the mechanism.
//
//   h = codyna_plant('open', 'model.json')            % optional: 'integrator', 'rtol', 'atol', 'max_step'
//   y = codyna_plant('step', h, u, dt)                % Plant/In u held for dt; returns Plant/Out at the end
//   y = codyna_plant('outputs', h)
//   [q, v, t] = codyna_plant('state', h)
//   codyna_plant('reset', h)                          % or codyna_plant('reset', h, q, v)
//   info = codyna_plant('info', h)                    % names, units, sizes
//   codyna_plant('close', h)
// Errors are Octave errors with identifiers codyna:plant:* and the model file's own messages.
#include <mex.h>

#include <map>
#include <memory>
#include <stdexcept>
#include <string>

#include "study/files.hpp"
#include "study/jobs.hpp"
#include "study/tools.hpp"

namespace {

using codyna::Model;
using codyna::Stepper;

struct Session {
  Model model;
  std::unique_ptr<Stepper> stepper;
};

std::map<int, std::unique_ptr<Session>>& sessions() {
  static std::map<int, std::unique_ptr<Session>> s;
  return s;
}
int next_handle = 1;

void close_all() { sessions().clear(); }

std::string text(const mxArray* a, const char* what) {
  if (!mxIsChar(a)) throw std::invalid_argument(std::string(what) + " must be a string");
  char* c = mxArrayToString(a);
  std::string s(c);
  mxFree(c);
  return s;
}

double scalar(const mxArray* a, const char* what) {
  if (!mxIsDouble(a) || mxIsComplex(a) || mxGetNumberOfElements(a) != 1)
    throw std::invalid_argument(std::string(what) + " must be a real scalar");
  return mxGetScalar(a);
}

Eigen::VectorXd vec(const mxArray* a, const char* what) {
  if (!mxIsDouble(a) || mxIsComplex(a)) throw std::invalid_argument(std::string(what) + " must be a real vector");
  const std::size_t n = mxGetNumberOfElements(a);
  return Eigen::Map<const Eigen::VectorXd>(mxGetPr(a), static_cast<Eigen::Index>(n));
}

mxArray* column(const Eigen::VectorXd& v) {
  mxArray* a = mxCreateDoubleMatrix(v.size(), 1, mxREAL);
  std::copy(v.data(), v.data() + v.size(), mxGetPr(a));
  return a;
}

mxArray* cellstr(const std::vector<std::string>& names) {
  mxArray* c = mxCreateCellMatrix(names.size(), 1);
  for (std::size_t k = 0; k < names.size(); ++k) mxSetCell(c, k, mxCreateString(names[k].c_str()));
  return c;
}

Session& session(const mxArray* h) {
  const int id = static_cast<int>(scalar(h, "the handle"));
  auto it = sessions().find(id);
  if (it == sessions().end()) throw std::invalid_argument("no open plant with handle " + std::to_string(id));
  return *it->second;
}

void open(int nlhs, mxArray* plhs[], int nrhs, const mxArray* prhs[]) {
  if (nrhs < 2 || nrhs % 2) throw std::invalid_argument("usage: h = codyna_plant('open', 'model.json', [name, value, ...])");
  const std::string path = text(prhs[1], "the model file");
  auto session_ptr = std::make_unique<Session>();
  session_ptr->model = codyna::study_compile(codyna::study_read_model(path), path);
  codyna::IntegratorSettings s = codyna::study_integrator_settings(session_ptr->model);
  for (int k = 2; k + 1 < nrhs; k += 2) {
    const std::string key = text(prhs[k], "an option name");
    if (key == "integrator") s.method = text(prhs[k + 1], "integrator");
    else if (key == "rtol") s.rtol = scalar(prhs[k + 1], "rtol");
    else if (key == "atol") s.atol = scalar(prhs[k + 1], "atol");
    else if (key == "max_step") s.max_step = scalar(prhs[k + 1], "max_step");
    else throw std::invalid_argument("unknown option '" + key + "' (integrator, rtol, atol, max_step)");
  }
  session_ptr->stepper = codyna::study_stepper(session_ptr->model, s);
  const int id = next_handle++;
  sessions()[id] = std::move(session_ptr);
  plhs[0] = mxCreateDoubleScalar(id);
  (void)nlhs;
}

void info(mxArray* plhs[], Session& s) {
  const Model& m = s.model;
  std::vector<std::string> in, in_units, out, out_units;
  for (int k : m.plant_inputs) {
    in.push_back(m.actuators[k].name);
    in_units.push_back(m.actuators[k].unit);
  }
  for (int k : m.plant_outputs) {
    out.push_back(m.sensors[k].name);
    out_units.push_back(m.sensors[k].unit);
  }
  const char* fields[] = {"model", "input_names", "input_units", "output_names", "output_units", "q_names", "v_names", "nq", "nv"};
  mxArray* st = mxCreateStructMatrix(1, 1, 9, fields);
  mxSetField(st, 0, "model", mxCreateString(m.name.c_str()));
  mxSetField(st, 0, "input_names", cellstr(in));
  mxSetField(st, 0, "input_units", cellstr(in_units));
  mxSetField(st, 0, "output_names", cellstr(out));
  mxSetField(st, 0, "output_units", cellstr(out_units));
  mxSetField(st, 0, "q_names", cellstr(m.q_names));
  mxSetField(st, 0, "v_names", cellstr(m.v_names));
  mxSetField(st, 0, "nq", mxCreateDoubleScalar(m.nq));
  mxSetField(st, 0, "nv", mxCreateDoubleScalar(m.nv));
  plhs[0] = st;
}

void dispatch(int nlhs, mxArray* plhs[], int nrhs, const mxArray* prhs[]) {
  if (nrhs < 1) throw std::invalid_argument("usage: codyna_plant(command, ...): open, step, outputs, state, reset, info, close");
  const std::string cmd = text(prhs[0], "the command");
  if (cmd == "open") return open(nlhs, plhs, nrhs, prhs);
  if (nrhs < 2) throw std::invalid_argument("codyna_plant('" + cmd + "', h, ...): the handle is missing");
  Session& s = session(prhs[1]);
  if (cmd == "step") {
    if (nrhs != 4) throw std::invalid_argument("usage: y = codyna_plant('step', h, u, dt)");
    plhs[0] = column(s.stepper->step(vec(prhs[2], "u"), scalar(prhs[3], "dt")));
  } else if (cmd == "outputs") {
    plhs[0] = column(s.stepper->outputs());
  } else if (cmd == "state") {
    plhs[0] = column(s.stepper->q());
    if (nlhs > 1) plhs[1] = column(s.stepper->v());
    if (nlhs > 2) plhs[2] = mxCreateDoubleScalar(s.stepper->time());
  } else if (cmd == "reset") {
    if (nrhs == 4) s.stepper->reset(0.0, vec(prhs[2], "q"), vec(prhs[3], "v"));
    else s.stepper->reset();
  } else if (cmd == "info") {
    info(plhs, s);
  } else if (cmd == "close") {
    sessions().erase(static_cast<int>(mxGetScalar(prhs[1])));
  } else {
    throw std::invalid_argument("unknown command '" + cmd + "' (open, step, outputs, state, reset, info, close)");
  }
}

}  // namespace

extern "C" void mexFunction(int nlhs, mxArray* plhs[], int nrhs, const mxArray* prhs[]) {
  static bool registered = false;
  if (!registered) {
    mexAtExit(close_all);
    registered = true;
  }
  std::string message;
  try {
    dispatch(nlhs, plhs, nrhs, prhs);
    return;
  } catch (const codyna::IntegratorFailure& e) {
    message = "solver failed at t = " + std::to_string(e.time()) + ": " + e.what();
  } catch (const std::exception& e) {
    message = e.what();
  }
  // raise the Octave error outside the C++ exception handlers (it does not return); Octave puts
  // the function's name in front of the message itself ("codyna_plant: ...")
  mexErrMsgIdAndTxt("codyna:plant", "%s", message.c_str());
}
