#include "insitu/colour_model.hpp"
