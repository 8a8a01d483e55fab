// Fixture of build.unity_clash_named: in one unity batch with a.cpp, number(2.0) below would call
// a.cpp's number(double), not this one.
#include <complex>
#include <string>

namespace demo {
namespace {

using cd = std::complex<double>;
constexpr double g = 9.8;
class Box {};

std::string number(cd z) { return std::to_string(z.real()) + "+" + std::to_string(z.imag()) + "i"; }

}  // namespace

// not local: a function of the same name in a named namespace is the linker's business
std::string shown(cd z) { return number(z); }

}  // namespace demo
