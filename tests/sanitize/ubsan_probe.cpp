// Shows that the sanitizer build's UBSan still checks the system's headers for
// the misuse cmake/ubsan_ignore.txt keeps: taking a row of an empty Eigen matrix
// is arithmetic on its null data pointer, inside Eigen's headers. The test
// sanitize.ubsan_in_eigen expects UBSan's report naming that; when the ignorelist
// (or a compiler) stops checking it, the report is missing and the test fails.
#include <Eigen/Dense>
#include <cstdio>

int main(int argc, char**) {
  Eigen::MatrixXd empty(3, argc - 1);  // no columns: data() is null
  const double* row = empty.row(1).data();
  std::printf("row at %p\n", static_cast<const void*>(row));
  return 0;
}
