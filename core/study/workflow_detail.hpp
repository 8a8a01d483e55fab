// Helpers the study's steps share (study/workflow.cpp: the model, the operating point, the
// linearization and export; study/workflow_handling.cpp: the handling numbers at a steady motion;
// study/workflow_simulation.cpp: the closed-loop run). Internal to
// study/: front ends use workflow.hpp.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "analysis/linearize.hpp"
#include "control/controllability.hpp"
#include "io/mat_export.hpp"
#include "model/model.hpp"
#include "simulation/simulator.hpp"
#include "study/workflow.hpp"

namespace codyna::workflow_detail {

std::string joined(const std::vector<std::string>& names);  // "a, b" ("" when empty)
std::string listed(const std::vector<std::string>& names);  // "a, b" ("none" when empty)
// a .mat read, its failure a std::invalid_argument (bad input, exit 1)
MatVariables read_mat_file_or_invalid(const std::string& path);
// ModelError at /analysis/FIELD of the model's file
[[noreturn]] void workflow_fail(const Model& m, const std::string& field, const std::string& what);
// a steady-state search that did not converge: a failure of the work (exit code 2), not bad input
[[noreturn]] void not_converged(const Model& m, const std::string& what);
JacobianMethod method_of_model(const Model& m);
SimulationOptions solver_options(const Model& m);  // the model file's solver settings
// diag(w) (n x n; identity when w is empty), the count and signs checked against /analysis/FIELD
Eigen::MatrixXd diagonal(const Model& m, const std::vector<double>& w, int n, const char* field);
// the study choices that define a plant, as the JSON text exported with it (codyna_study)
std::string plant_study_json(const StudySpec& s, const std::string& operating_point);
// the modes the inputs cannot move (an eigenvalue within round-off of 0 reported as 0)
std::vector<HiddenMode> uncontrollable(const LinearSystem& sys);
// `pairs` (coordinate or rate name -> value) set on (q, v) and the loops closed with them held;
// errors at /analysis/FIELD[/NAME] (study/workflow.cpp)
StudyInitialState set_coordinates(const Model& m, Eigen::VectorXd q, Eigen::VectorXd v,
                                  const std::vector<std::pair<std::string, double>>& pairs, const std::string& field);
// the handling numbers of a linearization about a steady motion (study/workflow_handling.cpp)
HandlingNumbers study_handling(const Model& m, const StudyLinearization& sl);
// an LQR needs every mode that does not decay by itself to be movable: says which are not
void require_stabilizable(const Model& m, const LinearSystem& sys);

}  // namespace codyna::workflow_detail
