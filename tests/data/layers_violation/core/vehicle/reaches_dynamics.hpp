// A vehicle file reaching into dynamics/ (the layer rule allows vehicle/ only itself and spatial/).
#pragma once
#include "dynamics/data.hpp"
