#include "io/results_file.hpp"

#include "io/hdf5_quiet.hpp"
#include "io/output_guard.hpp"

#include <hdf5.h>

#include <algorithm>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "io/atomic_file.hpp"
#include "io/hdf5_handle.hpp"

namespace codyna {
namespace {

using R = SimulationResult;
using Strings = std::vector<std::string>;
using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

constexpr int kFormatVersion = 1;

// ------------------------------------------------------------------ layout
// Tables shared by the writers, the reader and the consistency check, so that
// they cannot disagree.

struct MatrixField {
  const char* dataset;
  Eigen::MatrixXd R::*values;
  const char* names_dataset;
  Strings R::*names;
};
const MatrixField kMatrices[] = {
    {"/q", &R::q, "/names/q", &R::q_names},
    {"/v", &R::v, "/names/v", &R::v_names},
    {"/u", &R::u, "/names/inputs", &R::input_names},
    {"/y", &R::y, "/names/outputs", &R::output_names},
    {"/xc", &R::xc, "/names/controller_states", &R::controller_state_names},
};

// matrices present only when the run made them (0 x 0 otherwise), with as many columns as a kMatrices entry
struct OptionalField {
  const char* dataset;
  Eigen::MatrixXd R::*values;
  Eigen::MatrixXd R::*like;  // the matrix whose columns it has
  const char* like_dataset;
  Strings R::*names;
  const char* csv_suffix;
};
const OptionalField kOptional[] = {
    {"/y_linear", &R::y_linear, &R::y, "/y", &R::output_names, "_linear"},
    {"/y_reference", &R::y_reference, &R::y, "/y", &R::output_names, "_reference"},
    {"/u_disturbance", &R::u_disturbance, &R::u, "/u", &R::input_names, "_disturbance"},
};

// the effect states (a tire's contact deflections): written only when the model has them, so that
// the files of every other model keep their bytes
constexpr const char* kEffectStates = "/s";
constexpr const char* kEffectStateNames = "/names/effect_states";

struct SeriesField {
  const char* dataset;
  std::vector<double> R::*values;
  const char* csv_header;  // nullptr: HDF5 only
};
const SeriesField kSeries[] = {
    {"/energy/kinetic", &R::kinetic_energy, "kinetic_energy"},
    {"/energy/potential", &R::potential_energy, "potential_energy"},
    {"/constraints/position_violation", &R::constraint_violation, "constraint_violation"},
    {"/constraints/velocity_violation", &R::velocity_violation, nullptr},
};

struct UnitsField {
  const char* dataset;
  Strings R::*units;
  Strings R::*names;  // the list the units belong to
};
const UnitsField kUnits[] = {
    {"/units/inputs", &R::input_units, &R::input_names},
    {"/units/outputs", &R::output_units, &R::output_names},
};

constexpr const char* kSolver = "/solver";
const std::pair<const char*, double SolverStats::*> kSolverReals[] = {{"rtol", &SolverStats::rtol},
                                                                      {"atol", &SolverStats::atol},
                                                                      {"max_step", &SolverStats::max_step},
                                                                      {"wall_time", &SolverStats::wall_time}};
const std::pair<const char*, long SolverStats::*> kSolverCounts[] = {
    {"steps", &SolverStats::steps},
    {"rhs_evals", &SolverStats::rhs_evals},
    {"jac_evals", &SolverStats::jac_evals},
    {"error_test_failures", &SolverStats::error_test_failures},
    {"nonlinear_iterations", &SolverStats::nonlinear_iterations},
    {"nonlinear_failures", &SolverStats::nonlinear_failures},
    {"projections", &SolverStats::projections},
    {"restarts", &SolverStats::restarts}};

constexpr const char* kStatus = "/status";

constexpr const char* kProvenance = "/provenance";
const std::pair<const char*, std::string R::*> kProvenanceTexts[] = {{"model_name", &R::model_name},
                                                                     {"model_file", &R::model_file},
                                                                     {"controller", &R::controller},
                                                                     {"codyna_version", &R::codyna_version},
                                                                     {"settings_json", &R::settings_json}};

// ------------------------------------------------------------------ consistency

// What makes `r` impossible to store as one row per sample ("" if nothing).
std::string inconsistency(const R& r) {
  const std::size_t n = r.t.size();
  const std::string samples = " for " + std::to_string(n) + " samples (/time)";
  for (const SeriesField& f : kSeries)
    if ((r.*f.values).size() != n)
      return std::string(f.dataset) + " has " + std::to_string((r.*f.values).size()) + " entries" + samples;
  for (const MatrixField& f : kMatrices) {
    const Eigen::MatrixXd& m = r.*f.values;
    if (m.cols() > 0 && static_cast<std::size_t>(m.rows()) != n)
      return std::string(f.dataset) + " has " + std::to_string(m.rows()) + " rows" + samples;
    if ((r.*f.names).size() != static_cast<std::size_t>(m.cols()))
      return std::string(f.names_dataset) + " has " + std::to_string((r.*f.names).size()) + " entries for the " +
             std::to_string(m.cols()) + " columns of " + f.dataset;
  }
  for (const UnitsField& f : kUnits)
    if (!(r.*f.units).empty() && (r.*f.units).size() != (r.*f.names).size())
      return std::string(f.dataset) + " has " + std::to_string((r.*f.units).size()) + " entries for " +
             std::to_string((r.*f.names).size()) + " names";
  for (const OptionalField& f : kOptional) {
    const Eigen::MatrixXd& m = r.*f.values;
    const Eigen::Index cols = (r.*f.like).cols();
    if (m.cols() > 0 && (static_cast<std::size_t>(m.rows()) != n || m.cols() != cols))
      return std::string(f.dataset) + " is " + std::to_string(m.rows()) + " x " + std::to_string(m.cols()) +
             ", expected " + std::to_string(n) + " x " + std::to_string(cols) + " like " + f.like_dataset;
  }
  if (r.s.cols() > 0 && (static_cast<std::size_t>(r.s.rows()) != n || r.s_names.size() != static_cast<std::size_t>(r.s.cols())))
    return std::string(kEffectStates) + " is " + std::to_string(r.s.rows()) + " x " + std::to_string(r.s.cols()) + " with " +
           std::to_string(r.s_names.size()) + " names (" + kEffectStateNames + ")" + samples;
  return {};
}

void require_consistent(const R& r, const std::string& path) {
  if (const std::string problem = inconsistency(r); !problem.empty())
    throw std::runtime_error(path + ": inconsistent result: " + problem);
}

// ------------------------------------------------------------------ HDF5 plumbing

using FileError = Hdf5Error;
using Handle = Hdf5Handle;
void h5_check(herr_t rc, const std::string& what) { hdf5_check(rc, what); }

template <class T>
struct H5Type;
template <>
struct H5Type<double> {
  static hid_t file() { return H5T_IEEE_F64LE; }
  static hid_t memory() { return H5T_NATIVE_DOUBLE; }
};
template <>
struct H5Type<long> {
  static hid_t file() { return H5T_STD_I64LE; }
  static hid_t memory() { return H5T_NATIVE_LONG; }
};
template <>
struct H5Type<int> {
  static hid_t file() { return H5T_STD_I32LE; }
  static hid_t memory() { return H5T_NATIVE_INT; }
};

// Fixed-length, NUL-padded, tagged ASCII: what Octave's load() can read (see the header).
Handle fixed_string_type(std::size_t width, const std::string& what) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose, what);
  h5_check(H5Tset_size(type, width), what);
  h5_check(H5Tset_strpad(type, H5T_STR_NULLPAD), what);
  return type;
}

Handle utf8_text_type(const std::string& what) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose, what);
  h5_check(H5Tset_size(type, H5T_VARIABLE), what);
  h5_check(H5Tset_cset(type, H5T_CSET_UTF8), what);
  return type;
}

std::size_t element_count(const std::vector<hsize_t>& dims) {
  std::size_t n = 1;
  for (hsize_t d : dims) n *= static_cast<std::size_t>(d);
  return n;
}

// ------------------------------------------------------------------ writing

// Creates dataset `name` (and the groups on its path) with `dims` and writes
// `data` (row-major, in `memory_type`) to it.
void write_dataset(hid_t file, const std::string& name, hid_t file_type, hid_t memory_type,
                   const std::vector<hsize_t>& dims, const void* data) {
  const std::string what = "cannot write " + name;
  Handle space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose, what);
  Handle links(H5Pcreate(H5P_LINK_CREATE), H5Pclose, what);
  h5_check(H5Pset_create_intermediate_group(links, 1), what);
  Handle dataset(H5Dcreate2(file, name.c_str(), file_type, space, links, H5P_DEFAULT, H5P_DEFAULT), H5Dclose, what);
  if (element_count(dims) > 0) h5_check(H5Dwrite(dataset, memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), what);
}

// `m` as a (samples x columns) dataset; a matrix without columns is (samples x 0) whatever its rows.
void write_matrix(hid_t file, const std::string& name, const Eigen::MatrixXd& m, std::size_t samples) {
  const RowMajorMatrix rows = m;
  write_dataset(file, name, H5Type<double>::file(), H5Type<double>::memory(), {samples, static_cast<hsize_t>(m.cols())},
                rows.data());
}

void write_series(hid_t file, const std::string& name, const std::vector<double>& values) {
  write_dataset(file, name, H5Type<double>::file(), H5Type<double>::memory(), {values.size()}, values.data());
}

void write_strings(hid_t file, const std::string& name, const Strings& list) {
  std::size_t width = 1;  // HDF5 has no zero-length string type
  for (const std::string& s : list) width = std::max(width, s.size());
  std::vector<char> packed(list.size() * width, '\0');
  for (std::size_t i = 0; i < list.size(); ++i) std::memcpy(packed.data() + i * width, list[i].data(), list[i].size());
  const Handle type = fixed_string_type(width, "cannot write " + name);
  write_dataset(file, name, type, type, {list.size()}, packed.data());
}

void create_group(hid_t file, const char* name) {
  Handle group(H5Gcreate2(file, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose,
               std::string("cannot create group ") + name);
}

std::string attribute_label(const char* object, const char* name) {
  return std::string("attribute ") + name + " of " + object;
}

// A scalar attribute `name` of the object at path `object`.
void write_attribute(hid_t file, const char* object, const char* name, hid_t file_type, hid_t memory_type,
                     const void* value) {
  const std::string what = "cannot write " + attribute_label(object, name);
  Handle space(H5Screate(H5S_SCALAR), H5Sclose, what);
  Handle attribute(H5Acreate_by_name(file, object, name, file_type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                   H5Aclose, what);
  h5_check(H5Awrite(attribute, memory_type, value), what);
}

template <class T>
void write_attribute(hid_t file, const char* object, const char* name, const T& value) {
  write_attribute(file, object, name, H5Type<T>::file(), H5Type<T>::memory(), &value);
}

void write_attribute(hid_t file, const char* object, const char* name, const std::string& value) {
  const Handle type = utf8_text_type("cannot write " + attribute_label(object, name));
  const char* text = value.c_str();
  write_attribute(file, object, name, type, type, &text);
}

void write_contents(hid_t file, const R& r) {
  const std::size_t samples = r.t.size();
  write_attribute(file, "/", "format_version", kFormatVersion);
  write_series(file, "/time", r.t);
  for (const MatrixField& f : kMatrices) {
    write_matrix(file, f.dataset, r.*f.values, samples);
    write_strings(file, f.names_dataset, r.*f.names);
  }
  for (const OptionalField& f : kOptional)
    if ((r.*f.values).cols() > 0) write_matrix(file, f.dataset, r.*f.values, samples);
  if (r.s.cols() > 0) {
    write_matrix(file, kEffectStates, r.s, samples);
    write_strings(file, kEffectStateNames, r.s_names);
  }
  for (const SeriesField& f : kSeries) write_series(file, f.dataset, r.*f.values);
  for (const UnitsField& f : kUnits) write_strings(file, f.dataset, r.*f.units);

  create_group(file, kSolver);
  write_attribute(file, kSolver, "integrator", r.stats.integrator);
  for (const auto& [name, member] : kSolverReals) write_attribute(file, kSolver, name, r.stats.*member);
  for (const auto& [name, member] : kSolverCounts) write_attribute(file, kSolver, name, r.stats.*member);

  create_group(file, kStatus);
  write_attribute(file, kStatus, "completed", static_cast<int>(r.completed));
  write_attribute(file, kStatus, "cancelled", static_cast<int>(r.cancelled));
  write_attribute(file, kStatus, "failure", r.failure);

  create_group(file, kProvenance);
  for (const auto& [name, member] : kProvenanceTexts) write_attribute(file, kProvenance, name, r.*member);
}

// ------------------------------------------------------------------ reading

struct Dataset {
  Handle handle;
  std::vector<hsize_t> dims;
};

// Opens dataset `name`, which must have `rank` dimensions.
Dataset open_dataset(hid_t file, const std::string& name, int rank) {
  const std::string what = "cannot read " + name;
  Handle dataset(H5Dopen2(file, name.c_str(), H5P_DEFAULT), H5Dclose, what);
  Handle space(H5Dget_space(dataset), H5Sclose, what);
  const int found = H5Sget_simple_extent_ndims(space);
  if (found != rank)
    throw FileError(name + " has " + std::to_string(found) + " dimensions, expected " + std::to_string(rank));
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
  h5_check(H5Sget_simple_extent_dims(space, dims.data(), nullptr), what);
  return {std::move(dataset), std::move(dims)};
}

void read_dataset(const Dataset& d, const std::string& name, hid_t memory_type, void* data) {
  if (element_count(d.dims) > 0)
    h5_check(H5Dread(d.handle, memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), "cannot read " + name);
}

std::vector<double> read_series(hid_t file, const std::string& name) {
  const Dataset d = open_dataset(file, name, 1);
  std::vector<double> values(element_count(d.dims));
  read_dataset(d, name, H5Type<double>::memory(), values.data());
  return values;
}

Eigen::MatrixXd read_matrix(hid_t file, const std::string& name) {
  const Dataset d = open_dataset(file, name, 2);
  RowMajorMatrix rows(static_cast<Eigen::Index>(d.dims[0]), static_cast<Eigen::Index>(d.dims[1]));
  read_dataset(d, name, H5Type<double>::memory(), rows.data());
  return rows;
}

Strings read_strings(hid_t file, const std::string& name) {
  const std::string what = "cannot read " + name;
  const Dataset d = open_dataset(file, name, 1);
  const Handle stored(H5Dget_type(d.handle), H5Tclose, what);
  if (H5Tget_class(stored) != H5T_STRING || H5Tis_variable_str(stored) != 0)
    throw FileError(name + " is not a list of fixed-length strings");
  const std::size_t width = H5Tget_size(stored);
  const Handle type(H5Tcopy(stored), H5Tclose, what);  // same size and character set, NUL-padded
  h5_check(H5Tset_strpad(type, H5T_STR_NULLPAD), what);
  std::vector<char> packed(element_count(d.dims) * width);
  read_dataset(d, name, type, packed.data());
  Strings list;
  for (std::size_t at = 0; at < packed.size(); at += width)
    list.emplace_back(packed.data() + at, strnlen(packed.data() + at, width));
  return list;
}

void read_attribute(hid_t file, const char* object, const char* name, hid_t memory_type, void* value) {
  const std::string what = "cannot read " + attribute_label(object, name);
  Handle attribute(H5Aopen_by_name(file, object, name, H5P_DEFAULT, H5P_DEFAULT), H5Aclose, what);
  h5_check(H5Aread(attribute, memory_type, value), what);
}

template <class T>
T read_attribute(hid_t file, const char* object, const char* name) {
  T value{};
  read_attribute(file, object, name, H5Type<T>::memory(), &value);
  return value;
}

template <>
std::string read_attribute<std::string>(hid_t file, const char* object, const char* name) {
  const Handle type = utf8_text_type("cannot read " + attribute_label(object, name));
  char* text = nullptr;
  read_attribute(file, object, name, type, &text);
  std::string value = text ? text : "";
  H5free_memory(text);
  return value;
}

void require_format(hid_t file) {
  if (H5Aexists(file, "format_version") <= 0)
    throw FileError("not a codyna results file (the root has no format_version attribute)");
  const int version = read_attribute<int>(file, "/", "format_version");
  if (version != kFormatVersion)
    throw FileError("results format_version " + std::to_string(version) + " is not supported (this codyna reads " +
                    std::to_string(kFormatVersion) + ")");
}

R read_contents(hid_t file) {
  R r;
  r.t = read_series(file, "/time");
  for (const MatrixField& f : kMatrices) {
    r.*f.values = read_matrix(file, f.dataset);
    r.*f.names = read_strings(file, f.names_dataset);
  }
  for (const OptionalField& f : kOptional)
    if (H5Lexists(file, f.dataset, H5P_DEFAULT) > 0) r.*f.values = read_matrix(file, f.dataset);
  if (H5Lexists(file, kEffectStates, H5P_DEFAULT) > 0) {
    r.s = read_matrix(file, kEffectStates);
    r.s_names = read_strings(file, kEffectStateNames);
  }
  for (const SeriesField& f : kSeries) r.*f.values = read_series(file, f.dataset);
  for (const UnitsField& f : kUnits) r.*f.units = read_strings(file, f.dataset);

  r.stats.integrator = read_attribute<std::string>(file, kSolver, "integrator");
  for (const auto& [name, member] : kSolverReals) r.stats.*member = read_attribute<double>(file, kSolver, name);
  for (const auto& [name, member] : kSolverCounts) r.stats.*member = read_attribute<long>(file, kSolver, name);

  r.completed = read_attribute<int>(file, kStatus, "completed") != 0;
  r.cancelled = read_attribute<int>(file, kStatus, "cancelled") != 0;
  r.failure = read_attribute<std::string>(file, kStatus, "failure");

  for (const auto& [name, member] : kProvenanceTexts) r.*member = read_attribute<std::string>(file, kProvenance, name);
  return r;
}

// ------------------------------------------------------------------ CSV

struct CsvColumn {
  std::string header;
  const double* values;  // one per sample
};

// The columns in header order (see the header file).
std::vector<CsvColumn> csv_columns(const R& r) {
  std::vector<CsvColumn> columns{{"t", r.t.data()}};
  const auto add_matrix = [&](const Eigen::MatrixXd& m, const Strings& names, const std::string& suffix) {
    for (Eigen::Index j = 0; j < m.cols(); ++j)
      columns.push_back({names[static_cast<std::size_t>(j)] + suffix, m.col(j).data()});
  };
  for (const MatrixField& f : kMatrices) add_matrix(r.*f.values, r.*f.names, "");
  for (const SeriesField& f : kSeries)
    if (f.csv_header) columns.push_back({f.csv_header, (r.*f.values).data()});
  for (const OptionalField& f : kOptional) add_matrix(r.*f.values, r.*f.names, f.csv_suffix);  // none when absent
  add_matrix(r.s, r.s_names, "");  // the effect states, when the model has them
  return columns;
}

// RFC 4180: quoted only when needed, quotes doubled.
void append_csv_field(std::string& line, const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) {
    line += text;
    return;
  }
  line += '"';
  for (char c : text) line.append(c == '"' ? 2 : 1, c);
  line += '"';
}

// Like "%.17g" in the C locale, whatever the current locale.
void append_number(std::string& line, double x) {
  char buf[32];
  const auto result = std::to_chars(buf, buf + sizeof buf, x, std::chars_format::general, 17);
  line.append(buf, result.ptr);
}

// One CSV line of `count` fields, each appended by append_field(line, index).
template <class AppendField>
void append_csv_line(std::string& line, std::size_t count, AppendField append_field) {
  for (std::size_t c = 0; c < count; ++c) {
    if (c > 0) line += ',';
    append_field(line, c);
  }
  line += '\n';
}

}  // namespace

namespace {

void fill_hdf5(const SimulationResult& r, const std::string& path, const std::string& temp) {
  try {
    const QuietHdf5 quiet;
    Handle file(H5Fcreate(temp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose, "cannot create " + temp);
    write_contents(file, r);
    file.close("cannot finish " + temp);
  } catch (const FileError& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

void fill_csv(const SimulationResult& r, const std::string& path, const std::string& temp) {
  const std::vector<CsvColumn> columns = csv_columns(r);
  std::ofstream stream(temp, std::ios::binary | std::ios::trunc);
  std::string line;
  const auto write_line = [&](auto append_field) {
    line.clear();
    append_csv_line(line, columns.size(), append_field);
    stream.write(line.data(), static_cast<std::streamsize>(line.size()));
  };
  write_line([&](std::string& l, std::size_t c) { append_csv_field(l, columns[c].header); });
  for (std::size_t i = 0; i < r.t.size() && stream; ++i)
    write_line([&](std::string& l, std::size_t c) { append_number(l, columns[c].values[i]); });
  stream.close();
  if (!stream) throw std::runtime_error(path + ": cannot write " + temp);
}

}  // namespace

void write_results_hdf5(const SimulationResult& r, const std::string& path) {
  guard_output(path, OutputKind::ResultsHdf5, {r.model_file});
  require_consistent(r, path);
  AtomicFile out(path);
  fill_hdf5(r, path, out.temp_path());
  out.commit();
}

void write_results_csv(const SimulationResult& r, const std::string& path) {
  guard_output(path, OutputKind::ResultsCsv, {r.model_file});
  require_consistent(r, path);
  AtomicFile out(path);
  fill_csv(r, path, out.temp_path());
  out.commit();
}

void write_results(const SimulationResult& r, const std::string& hdf5_path, const std::string& csv_path) {
  if (csv_path.empty()) return write_results_hdf5(r, hdf5_path);
  guard_output(hdf5_path, OutputKind::ResultsHdf5, {r.model_file});
  guard_output(csv_path, OutputKind::ResultsCsv, {r.model_file});
  require_consistent(r, hdf5_path);
  // both complete before either is renamed into place: an interrupted run never leaves a
  // new .h5 beside an old .csv
  AtomicFile h5(hdf5_path), csv(csv_path);
  fill_hdf5(r, hdf5_path, h5.temp_path());
  fill_csv(r, csv_path, csv.temp_path());
  h5.commit();
  csv.commit();
}

SimulationResult read_results_hdf5(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw std::runtime_error(path + ": " + (ec ? ec.message() : "no such file"));
  try {
    const QuietHdf5 quiet;
    if (H5Fis_hdf5(path.c_str()) <= 0) throw FileError("not an HDF5 file");
    const Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose, "cannot open");
    require_format(file);
    SimulationResult r = read_contents(file);
    if (const std::string problem = inconsistency(r); !problem.empty())
      throw FileError("inconsistent results: " + problem);
    return r;
  } catch (const FileError& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

}  // namespace codyna
