// A front-end file that reaches past study/: the layer check must refuse it (layers.violation_refused).
#include "simulation/simulator.hpp"
#include "study/workflow.hpp"
