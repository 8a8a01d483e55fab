// What the side-by-side benchmarks against a peer (mujoco_speed_bench.cpp, pinocchio_bench.cpp)
// share: Google Benchmark's defaults for them (10 repetitions in random interleaved order,
// aggregates only), the median CPU time of each benchmark as the console reporter prints it,
// the table's number formats, and the run that prints the ratio table and writes it to a file.
#pragma once

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace codyna::bench {

// collects the median CPU time (ns) of every benchmark while the console reporter prints
class PeerCollector : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) {
      const std::string name = r.run_name.function_name;
      if (r.run_type == Run::RT_Aggregate) {
        if (r.aggregate_name == "median")
          median_ns_[name] = r.GetAdjustedCPUTime() / benchmark::GetTimeUnitMultiplier(r.time_unit) * 1e9;
      } else if (r.iterations > 0 && !r.error_occurred) {
        reps_ns_[name].push_back(r.cpu_accumulated_time / static_cast<double>(r.iterations) * 1e9);
      }
    }
    ConsoleReporter::ReportRuns(runs);
  }
  // the median over repetitions (Google Benchmark's own aggregate, else the runs'); -1 if none
  double get(const std::string& name) const {
    if (auto m = median_ns_.find(name); m != median_ns_.end()) return m->second;
    auto it = reps_ns_.find(name);
    if (it == reps_ns_.end() || it->second.empty()) return -1.0;
    std::vector<double> v = it->second;
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  }

 private:
  std::map<std::string, double> median_ns_;
  std::map<std::string, std::vector<double>> reps_ns_;
};

inline std::string peer_fmt_time(double ns) {
  char buf[32];
  if (ns < 0) return "-";
  if (ns < 1e4) std::snprintf(buf, sizeof buf, "%.3g us", ns * 1e-3);
  else if (ns < 1e7) std::snprintf(buf, sizeof buf, "%.4g us", ns * 1e-3);
  else std::snprintf(buf, sizeof buf, "%.4g ms", ns * 1e-6);
  return buf;
}

inline std::string peer_fmt_ratio(double a, double b) {
  if (a <= 0 || b <= 0) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", a / b);
  return buf;
}

// runs the registered benchmarks with the peer defaults added to args (unless given), prints the
// table made from the collected times and writes it to table_file (if not empty); exit status
inline int run_peer_benchmarks(const char* argv0, std::vector<std::string> args,
                               const std::function<std::string(const PeerCollector&)>& table,
                               const std::string& table_file) {
  auto has_flag = [&](const std::string& flag) {
    return std::any_of(args.begin(), args.end(), [&](const std::string& a) { return a.rfind(flag, 0) == 0; });
  };
  if (!has_flag("--benchmark_repetitions")) args.push_back("--benchmark_repetitions=10");
  if (!has_flag("--benchmark_enable_random_interleaving")) args.push_back("--benchmark_enable_random_interleaving=true");
  if (!has_flag("--benchmark_display_aggregates_only") && !has_flag("--benchmark_report_aggregates_only"))
    args.push_back("--benchmark_display_aggregates_only=true");
  std::string prog = argv0;
  std::vector<char*> bargv{prog.data()};
  for (std::string& a : args) bargv.push_back(a.data());
  int bargc = static_cast<int>(bargv.size());
  benchmark::Initialize(&bargc, bargv.data());
  if (benchmark::ReportUnrecognizedArguments(bargc, bargv.data())) return 1;
  PeerCollector collector;
  benchmark::RunSpecifiedBenchmarks(&collector);
  benchmark::Shutdown();
  const std::string t = table(collector);
  std::printf("\n%s", t.c_str());
  if (!table_file.empty()) {
    std::ofstream f(table_file);
    f << t;
    if (!f) {
      std::fprintf(stderr, "could not write %s\n", table_file.c_str());
      return 1;
    }
    std::printf("table written to %s\n", table_file.c_str());
  }
  return 0;
}

}  // namespace codyna::bench
