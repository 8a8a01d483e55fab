// Fixture of build.unity_clash_named (cmake/unity_names.py): local helpers that b.cpp defines too.
#include <complex>
#include <string>

namespace demo {
namespace {

using cd = std::complex<double>;  // the same alias in b.cpp: legal, not named
constexpr double m = 1.5, g = 9.81;
struct Box {
  double side;
};

std::string number(double x) { return std::to_string(x); }

}  // namespace

std::string shown(double x) { return number(x * m * g); }

}  // namespace demo
