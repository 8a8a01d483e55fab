// No heap allocation in one Linearizer::linearize into the same Linearization after the first
// call, on trees (the fast path: kept workspaces, names and partition copied into storage of the
// same sizes), at another operating point than the first call's, also after bind() to the same
// unchanged model; and linearize() alone, whose workspaces are kept per thread: it allocates
// what its result holds (as many allocations as copying that result), not its workspaces.
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
    long n = 0, rebound = 0, once = 0, copy = 0;
    {
      Count c;
      lz.linearize(op, {}, l);
      n = c.n();
    }
    {
      Count c;
      lz.bind(m);
      lz.linearize(op, {}, l);
      rebound = c.n();
    }
    (void)linearize(m, first);  // the thread's kept workspaces bound to m
    {
      Count c;
      const Linearization fresh = linearize(m, op);
      once = c.n();
      {
        Count c2;
        const Linearization again = fresh;
        copy = c2.n() + (again.system.A.size() == 0);
      }
    }
    EXPECT_EQ(n, 0) << label << ": heap allocations in one linearization into the same storage";
    EXPECT_EQ(rebound, 0) << label << ": heap allocations after bind() to the same unchanged model";
    EXPECT_EQ(once, copy) << label << ": linearize() alone allocates its result only";
    EXPECT_GT(copy, 10) << label;
    EXPECT_EQ(l.system.time, 1.5) << label;
  }
  EXPECT_GE(trees, 6);
}

}  // namespace
}  // namespace codyna
