// Writing the HDF5 files codyna makes with the HDF5 C API (io/sweep_files.cpp, study/freqresp_job.cpp):
// datasets and attributes with no modification times in the object headers, so that the same study
// gives the same bytes. Failures throw Hdf5Error (io/hdf5_handle.hpp) naming what was being written;
// use under a QuietHdf5 (io/hdf5_quiet.hpp).
#pragma once

#include <hdf5.h>

#include <cstdint>
#include <string>
#include <vector>

#include "io/hdf5_handle.hpp"

namespace codyna::h5 {

// a property list of class cls without object modification times
Hdf5Handle untimed(hid_t cls, const std::string& what);
void create_group(hid_t file, const std::string& name);
// dims: the dataset's shape (row-major, C order); data: its elements in memory_type
void write_dataset(hid_t file, const std::string& name, hid_t file_type, hid_t memory_type, const std::vector<hsize_t>& dims,
                   const void* data);
void write_doubles(hid_t file, const std::string& name, const std::vector<hsize_t>& dims, const std::vector<double>& v);
void write_ints(hid_t file, const std::string& name, const std::vector<int>& v);
// fixed-width, null-padded strings (the longest's width)
void write_strings(hid_t file, const std::string& name, const std::vector<std::string>& list);
// scalar attributes of the object `object` ("/" for the file)
void write_attribute(hid_t file, const char* object, const char* name, hid_t ftype, hid_t mtype, const void* value);
void write_attribute(hid_t file, const char* object, const char* name, const std::string& value);  // UTF-8, variable length
void write_attribute(hid_t file, const char* object, const char* name, long long value);
void write_attribute_u64(hid_t file, const char* object, const char* name, std::uint64_t value);

}  // namespace codyna::h5
