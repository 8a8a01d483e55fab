#include "io/sweep_data.hpp"

#include <cmath>
#include <numbers>

namespace codyna {

namespace {
// ------------------------------------------------------------------ random numbers
// Counter-based: every number is a hash of (seed, variant, field, draw), so variant i never
// depends on which variants ran before it, on which thread, or in which process.

}  // namespace

std::uint64_t sweep_mix64(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// uniform on the open interval (0, 1), 53 bits
namespace {

double sweep_unit_draw(std::uint64_t seed, long long i, std::size_t k, int draw) {
  std::uint64_t h = sweep_mix64(seed);
  h = sweep_mix64(h ^ static_cast<std::uint64_t>(i));
  h = sweep_mix64(h ^ static_cast<std::uint64_t>(k));
  h = sweep_mix64(h ^ static_cast<std::uint64_t>(draw));
  return (static_cast<double>(h >> 11) + 0.5) * 0x1.0p-53;
}

}  // namespace

std::vector<double> SweepPlan::values(long long i) const {
  std::vector<double> out(vary.size());
  if (!random) {
    long long rest = i;
    for (std::size_t k = vary.size(); k-- > 0;) {
      const long long n = static_cast<long long>(vary[k].values.size());
      out[k] = vary[k].values[static_cast<std::size_t>(rest % n)];
      rest /= n;
    }
    return out;
  }
  for (std::size_t k = 0; k < vary.size(); ++k) {
    const SweepVary& v = vary[k];
    if (v.kind == SweepVary::Uniform) {
      out[k] = v.a + (v.b - v.a) * sweep_unit_draw(seed, i, k, 0);
    } else {  // Box-Muller on two draws of its own
      const double u1 = sweep_unit_draw(seed, i, k, 0), u2 = sweep_unit_draw(seed, i, k, 1);
      out[k] = v.a + v.b * std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
    }
  }
  return out;
}

const char* to_string(SweepStatus s) {
  switch (s) {
    case SweepStatus::Ok: return "ok";
    case SweepStatus::ModelError: return "model error";
    case SweepStatus::NotConverged: return "not converged";
    case SweepStatus::Refused: return "refused";
    case SweepStatus::Failed: return "failed";
    case SweepStatus::SizeDiffers: return "sizes differ";
  }
  return "failed";
}

}  // namespace codyna
