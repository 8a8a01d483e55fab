// The parameter study's variants (study/sweep.cpp's job runs them; internal to study/): what a
// variant's model is (the nominal spec with the varied elements read again, or the whole file
// read again), its linearization, poles and controllability, and its closed-loop run.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "study/sweep.hpp"

namespace codyna::sweep_detail {

// The varied fields of one element of the model file's arrays (/bodies/1/mass, /bodies/1/com/0):
// a variant reads that element again into a copy of the nominal spec (io/model_file.hpp,
// parse_model_element), the rest of the file is not read again.
struct ElementEdit {
  std::string section;
  std::size_t index = 0;
  std::vector<std::pair<nlohmann::json::json_pointer, std::size_t>> fields;  // below the element; which value
};

struct Context {
  const SweepRequest* request;
  const SweepPlan* plan;
  const nlohmann::json* file;
  const ModelSpec* nominal = nullptr;
  std::vector<nlohmann::json::json_pointer> pointers;
  std::vector<ElementEdit> edits;
  bool whole_file = false;  // a varied field outside the element arrays: each variant's file is read whole
  // the nominal model's tree, names and indices when the varied fields leave them as they are
  // (numbers_changed, study_linearize_structure): a variant makes what it changes in a copy
  const Model* structure = nullptr;
  NumbersChanged changed;
  LinearizeRequest linearize;
  int nx = 0, nu = 0, ny = 0;
  std::vector<std::string> state_names;
  bool closed_loop = false, redesign = false, simulate = false;
  bool replace_controller = false;  // simulate with K fixed: the file's controller becomes a state feedback K
  std::string controller_point;     // where that state feedback is applied
  Eigen::MatrixXd K;
};

// eig(A) sorted by real part, then imaginary part; the largest real part (-inf when empty);
// asymptotically stable by the one rule (analysis/stability.hpp)
Eigen::VectorXcd poles_of(const Eigen::MatrixXd& A);
double max_real(const Eigen::VectorXcd& p);
bool stable_poles(const Eigen::VectorXcd& p, const Eigen::MatrixXd& A, bool discrete);
std::string joined(const std::vector<std::string>& v);

// What the varied fields change of the compiled model (nothing structural: the nominal tree is
// reused), or nullopt when a variant must be compiled anew
std::optional<NumbersChanged> numbers_changed(const std::vector<SweepVary>& vary);
// c.edits / c.pointers / c.whole_file for the plan's fields
void plan_edits(Context& c, const std::vector<SweepVary>& vary);
// variant i: its model, linearization, poles, controllability and (c.simulate) its run
void run_variant(const Context& c, long long i, SweepVariant& v);

}  // namespace codyna::sweep_detail
