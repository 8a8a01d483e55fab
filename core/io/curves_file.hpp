// The curves of a linear closed loop (analysis/closed_loop_linear.hpp) as CSV, one header
// line then one line per sample, numbers with 17 significant digits in the C locale:
//
//   step       t,OUT/IN,...           every output's response to a unit step on each input
//                                     (inputs outer, outputs inner: h/r_h, theta/r_h, ...)
//   frequency  w,OUT/IN:mag,OUT/IN:phase_deg,...   w in rad/s, |H| and the unwrapped phase
//
// OUT and IN are the closed loop's output and input names. Written atomically; an existing
// file is replaced only when codyna wrote it (io/output_guard.hpp), never a model file.
#pragma once

#include <string>

#include "analysis/closed_loop_linear.hpp"

namespace codyna {

void write_step_csv(const ClosedLoopLinear& cl, const StepResponse& step, const std::string& path);
void write_frequency_csv(const ClosedLoopLinear& cl, const FrequencyResponse& f, const std::string& path);

}  // namespace codyna
