// No heap allocation in one Linearizer::linearize into the same Linearization after the first
// call, on trees (the fast path: kept workspaces, names and partition copied into storage of the
// same sizes), at another operating point than the first call's; and one counted for linearize()
// alone, which makes its workspaces (so that a change that lets the fast path allocate is seen
// against a number that is not zero).
#include <gtest/gtest.h>

#include <filesystem>

#include "analysis/linearizer.hpp"
#include "analysis/operating_point.hpp"
#include "dynamics/prepare.hpp"
#include "io/model_file.hpp"
#include "counting_allocator.hpp"

namespace codyna {
namespace {

using alloc_test::Count;

Model load(const std::string& path) { return compile(load_model_spec(path), path); }

TEST(NoAllocation, LinearizerIntoTheSameLinearizationOnEveryTreeExample) {
  int trees = 0;
  for (const auto& entry : std::filesystem::directory_iterator(CODYNA_EXAMPLES_DIR)) {
    if (entry.path().extension() != ".json") continue;
    const Model m = load(entry.path().string());
    if (m.nc != 0 || !m.motions.empty()) continue;
    ++trees;
    const std::string label = entry.path().filename().string();
    const OperatingPoint first = initial_point(m);
    OperatingPoint op = first;
    for (int k = 0; k < m.nv; ++k) op.v[k] += 0.3 + 0.1 * k;
    for (int i : m.plant_inputs) op.u[i] += 0.7;
    op.t = 1.5;
    Linearizer lz(m);
    Linearization l;
    lz.linearize(first, {}, l);  // warm-up: the workspaces and the storage of l are made here
    long n = 0, once = 0;
    {
      Count c;
      lz.linearize(op, {}, l);
      n = c.n();
    }
    {
      Count c;
      const Linearization fresh = linearize(m, op);
      once = c.n() + (fresh.system.A.size() == 0);
    }
    EXPECT_EQ(n, 0) << label << ": heap allocations in one linearization into the same storage";
    EXPECT_GT(once, 10) << label << ": linearize() alone makes its workspaces";
    EXPECT_EQ(l.system.time, 1.5) << label;
  }
  EXPECT_GE(trees, 6);
}

}  // namespace
}  // namespace codyna
