// The simulation layer reading a file itself: refused (layers.violation_refused).
#include "io/mat_export.hpp"
