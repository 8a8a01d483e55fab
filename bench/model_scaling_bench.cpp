// Loading and compiling a model stays close to linear in the number of bodies:
// a 3-D hinge chain of N links (alternating axes, boxes), written as JSON text,
// parsed, compiled (tree ordering, assembly, the O(n) mass-matrix check), as
// `codyna info` does. Google Benchmark fits the complexity (BigO).
//   build/bin/codyna_bench_model_scaling
#include <benchmark/benchmark.h>

#include <string>

#include "io/model_file.hpp"
#include "dynamics/prepare.hpp"

namespace {

std::string chain_json(int n) {
  std::string b, j;
  for (int i = 0; i < n; ++i) {
    const std::string id = std::to_string(i);
    b += std::string(i ? "," : "") + R"({"name": "b)" + id +
         R"(", "mass": 1, "com": [0.5, 0, 0], "inertia": [0.01, 0.1, 0.1, 0, 0, 0], "shapes": [{"type": "box", "size": [1, 0.1, 0.1]}]})";
    j += std::string(i ? "," : "") + R"({"name": "j)" + id + R"(", "type": "revolute", "parent": ")" +
         (i ? "b" + std::to_string(i - 1) : std::string("ground")) + R"(", "child": "b)" + id + R"(", "axis": )" +
         (i % 2 ? "[0, 1, 0]" : "[0, 0, 1]") + R"(, "parent_frame": {"position": [)" + (i ? "1" : "0") + R"(, 0, 0]}})";
  }
  return R"({"name": "chain", "bodies": [)" + b + R"(], "joints": [)" + j +
         R"(], "effects": [{"name": "g", "type": "gravity", "g": [0, -9.81, 0]}]})";
}

void LoadAndCompileChain(benchmark::State& state) {
  const std::string text = chain_json(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    const codyna::Model m = codyna::compile(codyna::parse_model_spec_text(text, "chain.json"), "chain.json");
    benchmark::DoNotOptimize(m.nv);
  }
  state.SetComplexityN(state.range(0));
}

}  // namespace

BENCHMARK(LoadAndCompileChain)->RangeMultiplier(2)->Range(125, 4000)->Unit(benchmark::kMillisecond)->Complexity();
BENCHMARK_MAIN();
