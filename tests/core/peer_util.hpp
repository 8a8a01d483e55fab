// Test helpers for peer checks: running outside programs (GNU Octave, python3)
// from a test, quoting their arguments, and exchanging matrices with Octave.
// Shared by the tests that compare codyna with its peers (lqr, place,
// mat_export, results_file).
#pragma once

#include <sys/wait.h>

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace codyna::test {

// What a shell command did: its exit code (-1 when it did not exit normally or
// could not start) and everything it wrote.
struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

// Runs `command` through /bin/sh with stderr merged into stdout, so a failing
// peer's own explanation ends up in the assertion message.
inline CommandResult run_command(const std::string& command) {
  CommandResult r;
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buf;
  while (std::size_t n = std::fread(buf.data(), 1, buf.size(), pipe)) r.output.append(buf.data(), n);
  const int status = ::pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// Whether `program` can be run, so a test can skip when its peer is not installed.
inline bool on_path(const std::string& program) { return run_command("command -v " + program).exit_code == 0; }

// `s` as one single-quoted shell word, so paths and scripts with spaces or
// quotes reach the peer unchanged.
inline std::string shell_quoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// `command` stopped after 60 s where coreutils' timeout exists (a hung peer must not hang CTest)
inline std::string bounded(const std::string& command) {
  static const bool have_timeout = on_path("timeout");
  return (have_timeout ? "timeout 60 " : "") + command;
}

// The folder of the peer scripts (tests/peers), so a test finds them from any working directory.
inline std::string peers_dir() { return std::string(CODYNA_SOURCE_DIR) + "/tests/peers"; }

// The path of tests/peers/<file> (with an empty `file`, the folder with a trailing slash).
inline std::string peer_script(const std::string& file) { return peers_dir() + "/" + file; }

// A python3 that can `import <modules>` (e.g. "numpy, h5py"): $CODYNA_PYTHON,
// python3 on PATH, or the system one; none when no candidate has them, so the
// test can skip with a hint instead of failing.
inline std::optional<std::string> python_with(const std::string& modules) {
  std::vector<std::string> candidates;
  if (const char* env = std::getenv("CODYNA_PYTHON")) candidates.push_back(env);
  candidates.insert(candidates.end(), {"python3", "/usr/bin/python3"});
  for (const std::string& py : candidates)
    if (run_command(shell_quoted(py) + " -c 'import " + modules + "'").exit_code == 0) return py;
  return std::nullopt;
}

// max |a - b| over max |b| (0 when both are zero); infinite on a size mismatch.
// The one measure of agreement the peer comparisons report and bound.
inline double relative_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return std::numeric_limits<double>::infinity();
  const double scale = b.cwiseAbs().maxCoeff();
  const double err = (a - b).cwiseAbs().maxCoeff();
  return err == 0 ? 0 : err / scale;
}

// An Octave matrix literal that reproduces every double exactly ("%.17g"), so
// Octave solves the very problem codyna solved.
inline std::string octave_literal(const Eigen::MatrixXd& M) {
  std::string s = "[";
  char buf[32];
  for (Eigen::Index i = 0; i < M.rows(); ++i) {
    for (Eigen::Index j = 0; j < M.cols(); ++j) {
      std::snprintf(buf, sizeof buf, "%.17g", M(i, j));
      s += (j ? " " : "") + std::string(buf);
    }
    s += i + 1 < M.rows() ? "; " : "";
  }
  return s + "]";
}

// Octave code that prints "CODYNA <name> <rows> <cols> <column-major values>",
// the line parse_matrix reads back at full precision.
inline std::string octave_print(const std::string& name) {
  return "printf('CODYNA " + name + " %d %d', rows(" + name + "), columns(" + name + ")); printf(' %.17g', " + name +
         "); printf('\\n'); ";
}

// The matrix that octave_print(name) printed into `output`; throws with the
// whole output when it is missing or cut short.
inline Eigen::MatrixXd parse_matrix(const std::string& output, const std::string& name) {
  const std::string key = "CODYNA " + name + " ";
  const auto at = output.find(key);
  if (at == std::string::npos) throw std::runtime_error("no " + name + " in Octave's output:\n" + output);
  std::istringstream in(output.substr(at + key.size()));
  int rows = 0, cols = 0;
  in >> rows >> cols;
  Eigen::MatrixXd M(rows, cols);
  for (Eigen::Index k = 0; k < M.size(); ++k) in >> M.data()[k];  // both column-major
  if (!in) throw std::runtime_error("cannot read " + name + " from Octave's output:\n" + output);
  return M;
}

// Runs `body` in octave-cli (bounded) with the control package; the marker
// CODYNA_PEER_DONE it prints last proves it got to the end.
inline CommandResult run_octave(const std::string& body) {
  const std::string script = "pkg load control; " + body + " disp('CODYNA_PEER_DONE');";
  return run_command(bounded("octave-cli --no-gui --quiet --norc --eval " + shell_quoted(script)));
}

}  // namespace codyna::test
