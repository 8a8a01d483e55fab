// The model layer calling the algorithms above it: refused (layers.violation_refused).
#include "dynamics/crba.hpp"
#include "model/model.hpp"
