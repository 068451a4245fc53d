#include "insitu/view_synthesis.hpp"
