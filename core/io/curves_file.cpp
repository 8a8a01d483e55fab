#include "io/curves_file.hpp"

#include <fstream>
#include <locale>
#include <sstream>
#include <stdexcept>

#include "io/atomic_file.hpp"
#include "io/output_guard.hpp"

namespace codyna {

namespace {

// a header field, quoted when it holds a comma, a quote or a line break
std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

template <class Fill>
void write_csv(const std::string& path, const std::string& model_file, Fill fill) {
  guard_output(path, OutputKind::CurvesCsv, {model_file});
  AtomicFile out(path);
  {
    std::ofstream stream(out.temp_path(), std::ios::binary | std::ios::trunc);
    std::ostringstream text;
    text.imbue(std::locale::classic());
    text.precision(17);
    fill(text);
    const std::string s = text.str();
    stream.write(s.data(), static_cast<std::streamsize>(s.size()));
    stream.close();
    if (!stream) throw std::runtime_error(path + ": cannot write " + out.temp_path());
  }
  out.commit();
}

}  // namespace

void write_step_csv(const ClosedLoopLinear& cl, const StepResponse& step, const std::string& path) {
  const LinearSystem& s = cl.system;
  write_csv(path, s.model_file, [&](std::ostringstream& os) {
    os << "t";
    for (const std::string& in : s.input_names)
      for (const std::string& out : s.output_names) os << "," << csv_field(out + "/" + in);
    os << "\n";
    for (std::size_t k = 0; k < step.t.size(); ++k) {
      os << step.t[k];
      for (const Eigen::MatrixXd& Y : step.y)
        for (Eigen::Index i = 0; i < Y.cols(); ++i) os << "," << Y(static_cast<Eigen::Index>(k), i);
      os << "\n";
    }
  });
}

void write_frequency_csv(const ClosedLoopLinear& cl, const FrequencyResponse& f, const std::string& path) {
  const LinearSystem& s = cl.system;
  write_csv(path, s.model_file, [&](std::ostringstream& os) {
    os << "w";
    for (const std::string& in : s.input_names)
      for (const std::string& out : s.output_names)
        os << "," << csv_field(out + "/" + in + ":mag") << "," << csv_field(out + "/" + in + ":phase_deg");
    os << "\n";
    for (std::size_t k = 0; k < f.w.size(); ++k) {
      os << f.w[k];
      for (Eigen::Index j = 0; j < f.magnitude[k].cols(); ++j)
        for (Eigen::Index i = 0; i < f.magnitude[k].rows(); ++i)
          os << "," << f.magnitude[k](i, j) << "," << f.phase_deg[k](i, j);
      os << "\n";
    }
  });
}

}  // namespace codyna
