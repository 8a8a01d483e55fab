// The worked example of docs/ARCHITECTURE.md ("Adding a study"): a new study, its Request, Job
// and Report, written in the fewest lines on the study/ door, compiled and run here; the page
// shows the text between the markers below, and the CTest test docs.architecture_example checks
// that the page shows it unchanged.
#include <gtest/gtest.h>

#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "io/model_file.hpp"
#include "study/jobs.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

// [architecture example]
// 1. The request: typed, every field optional (what is not given keeps the model file's study).
struct OpenLoopRequest {
  OptionStyle style = OptionStyle::Flag;       // how refusals name the options
  std::string model;                           // the model file (messages, relative paths)
  std::optional<std::string> operating_point;  // initial | equilibrium | trim | time=T
};

// 2. The report: every number and every classification a front end shows, decided here once.
struct OpenLoopReport {
  std::string point;        // the operating point's kind
  ModalAnalysis modes;      // each mode with its Stability (analysis/stability.hpp, the one rule)
  PoleCount count;          // how many are stable, marginal, unstable
  std::vector<std::string> notes;
};

// 3. The job: the request on top of the file's study, the study's steps in order.
OpenLoopReport open_loop_job(const OpenLoopRequest& r, ModelSpec spec) {
  if (r.operating_point) {
    if (r.operating_point->empty())
      throw std::invalid_argument(option_name(r.style, "operating-point") + ": expected initial, equilibrium, trim or time=T");
    spec.analysis.operating_point = *r.operating_point;
  }
  const Model m = study_model(spec, r.model);
  const StudyLinearization lin = study_linearize(m);
  OpenLoopReport report;
  report.point = lin.op.kind;
  report.modes = study_modes(lin.system);
  report.count = count_stability(report.modes);
  if (report.count.unstable > 0)
    report.notes.push_back(std::to_string(report.count.unstable) + " unstable mode(s) about the " + report.point + " point");
  return report;
}

// 4. A front end renders the report and decides nothing (the CLI's text; Python converts the
// same fields, the GUI shows them in its widgets).
std::string open_loop_text(const OpenLoopReport& r) {
  std::ostringstream os;
  os << "operating point  " << r.point << "\n" << study_format_modes(r.modes) << "\nstable " << r.count.stable
     << ", marginal " << r.count.marginal << ", unstable " << r.count.unstable << "\n";
  for (const std::string& n : r.notes) os << "note: " << n << "\n";
  return os.str();
}
// [end of architecture example]

}  // namespace

// The example's report says what the linearize job says of the same model: the upright pendulum
// on its cart has one unstable mode, the cart's double zero (marginal) and one stable mode
TEST(StudyExample, TheWorkedExampleRunsAndAgreesWithTheLinearizeJob) {
  const std::string path = test::example_path("cart_pendulum.json");
  const ModelSpec spec = load_model_spec(path);
  OpenLoopRequest r;
  r.model = path;
  const OpenLoopReport report = open_loop_job(r, spec);
  LinearizeRequest lr;
  lr.model = path;
  const LinearizeJob job = study_linearize_job(lr, spec);
  EXPECT_EQ(report.point, job.linearization.op.kind);
  ASSERT_EQ(report.modes.modes.size(), job.modes.modes.size());
  for (std::size_t k = 0; k < report.modes.modes.size(); ++k) {
    EXPECT_EQ(report.modes.modes[k].eigenvalue, job.modes.modes[k].eigenvalue);
    EXPECT_EQ(report.modes.modes[k].stability, job.modes.modes[k].stability);
  }
  EXPECT_EQ(report.count.unstable, 1);
  EXPECT_EQ(report.count.marginal, 2);
  EXPECT_EQ(report.count.stable, 1);
  const std::string text = open_loop_text(report);
  EXPECT_NE(text.find("stable 1, marginal 2, unstable 1"), std::string::npos) << text;
  EXPECT_NE(text.find("note: 1 unstable mode(s) about the equilibrium point"), std::string::npos) << text;
  r.operating_point = "";
  r.style = OptionStyle::Keyword;
  EXPECT_INVALID_ARGUMENT_WITH(open_loop_job(r, spec), "operating_point: expected initial");
}

}  // namespace codyna
