#include "io/hdf5_write.hpp"

#include <algorithm>
#include <cstring>

namespace codyna::h5 {

Hdf5Handle untimed(hid_t cls, const std::string& what) {
  Hdf5Handle p(H5Pcreate(cls), H5Pclose, what);
  hdf5_check(H5Pset_obj_track_times(p, 0), what);
  return p;
}

void create_group(hid_t file, const std::string& name) {
  const std::string what = "cannot create group " + name;
  const Hdf5Handle gcpl = untimed(H5P_GROUP_CREATE, what);
  Hdf5Handle g(H5Gcreate2(file, name.c_str(), H5P_DEFAULT, gcpl, H5P_DEFAULT), H5Gclose, what);
}

void write_dataset(hid_t file, const std::string& name, hid_t file_type, hid_t memory_type, const std::vector<hsize_t>& dims,
                   const void* data) {
  const std::string what = "cannot write " + name;
  Hdf5Handle space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose, what);
  const Hdf5Handle dcpl = untimed(H5P_DATASET_CREATE, what);
  Hdf5Handle d(H5Dcreate2(file, name.c_str(), file_type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT), H5Dclose, what);
  std::size_t count = 1;
  for (hsize_t x : dims) count *= static_cast<std::size_t>(x);
  if (count > 0) hdf5_check(H5Dwrite(d, memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), what);
}

void write_doubles(hid_t file, const std::string& name, const std::vector<hsize_t>& dims, const std::vector<double>& v) {
  write_dataset(file, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, dims, v.data());
}

void write_ints(hid_t file, const std::string& name, const std::vector<int>& v) {
  write_dataset(file, name, H5T_STD_I32LE, H5T_NATIVE_INT, {v.size()}, v.data());
}

void write_strings(hid_t file, const std::string& name, const std::vector<std::string>& list) {
  std::size_t width = 1;
  for (const std::string& s : list) width = std::max(width, s.size());
  std::vector<char> packed(list.size() * width, '\0');
  for (std::size_t i = 0; i < list.size(); ++i) std::memcpy(packed.data() + i * width, list[i].data(), list[i].size());
  const std::string what = "cannot write " + name;
  Hdf5Handle type(H5Tcopy(H5T_C_S1), H5Tclose, what);
  hdf5_check(H5Tset_size(type, width), what);
  hdf5_check(H5Tset_strpad(type, H5T_STR_NULLPAD), what);
  write_dataset(file, name, type, type, {list.size()}, packed.data());
}

void write_attribute(hid_t file, const char* object, const char* name, hid_t ftype, hid_t mtype, const void* value) {
  const std::string what = std::string("cannot write attribute ") + name + " of " + object;
  Hdf5Handle space(H5Screate(H5S_SCALAR), H5Sclose, what);
  Hdf5Handle a(H5Acreate_by_name(file, object, name, ftype, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Aclose, what);
  hdf5_check(H5Awrite(a, mtype, value), what);
}
void write_attribute(hid_t file, const char* object, const char* name, const std::string& value) {
  const std::string what = std::string("cannot write attribute ") + name;
  Hdf5Handle type(H5Tcopy(H5T_C_S1), H5Tclose, what);
  hdf5_check(H5Tset_size(type, H5T_VARIABLE), what);
  hdf5_check(H5Tset_cset(type, H5T_CSET_UTF8), what);
  const char* text = value.c_str();
  write_attribute(file, object, name, type, type, &text);
}
void write_attribute(hid_t file, const char* object, const char* name, long long value) {
  write_attribute(file, object, name, H5T_STD_I64LE, H5T_NATIVE_LLONG, &value);
}
void write_attribute_u64(hid_t file, const char* object, const char* name, std::uint64_t value) {
  write_attribute(file, object, name, H5T_STD_U64LE, H5T_NATIVE_UINT64, &value);
}

}  // namespace codyna::h5
