// The tire test rig (issue 39, `codyna tire`): a tire model evaluated over a grid of load,
// longitudinal slip, slip angle and camber at one speed, with the code the simulation uses
// (dynamics/tire_effect.hpp's law: linear, Fiala or the Magic Formula), written as CSV in MFeval's
// column order.
//   the tire: a .tir file (the Magic Formula, mounted as the file says or on a side), or a model
//     file's tire element by name (its law and numbers, as a simulation uses them)
//   the grid: every combination of the given loads (N; default 0.5, 1 and 1.5 times the .tir's
//     FNOMIN), slips kappa (-), slip angles alpha (rad) and cambers gamma (rad) (each default 0),
//     at forward speed Vx (m/s)
//   the columns (ISO-W axes, SI units; tires.md): Fx Fy Fz Mx My Mz kappa alpha gamma phit Vx Re
//     t mux muy omega Mzr Kya Kxk (MFeval's outMF order, the columns codyna does not compute left
//     out: pressure, contact patch, stiffnesses Cx Cy Cz, relaxation lengths)
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace codyna {

struct ModelSpec;

struct TireRequest {
  std::string tir;                   // a .tir file, or
  std::string model, tire;           // a model file and the name of its tire element
  const ModelSpec* spec = nullptr;   // or the model as edited (a GUI's document), read instead of
                                     // the file `model`, which then only places relative paths
                                     // (its .tir files) and names it in messages ("" when unsaved)
  std::string side;                  // .tir: "" (as the file), "left" or "right"
  std::vector<double> loads, kappa, alpha, gamma;
  // no loads given and the tire has no nominal load (a linear or Fiala tire; a .tir has FNOMIN):
  // true: 2, 4 and 6 kN (a passenger car's corner, what a window draws first); false: refused
  // (--load: give the loads)
  bool typical_loads = false;
  double speed = 16.7;               // m/s
  std::string out;                   // the CSV file ("" = none: the job's rows only)
};

struct TireJob {
  std::string tire;                  // what was evaluated ("FILE.tir (MF 6.1, left)", "model.json: front_tire (fiala)")
  std::vector<std::string> columns;  // in order
  Eigen::MatrixXd rows;              // one per grid point
  std::vector<std::string> notes;
  std::string written;               // the CSV written ("" when none)
};

// Throws std::invalid_argument for a bad request (naming the option: --tir, --model, --tire,
// --side, --load, --kappa, --alpha, --gamma, --speed), ModelError for a bad .tir or model file.
TireJob study_tire_job(const TireRequest& request);

// A grid's values from "A:B:N" (N points from A to B), "V1,V2,..." or one number; `option` names it
// in errors.
std::vector<double> study_tire_grid(const std::string& text, const std::string& option);

}  // namespace codyna
