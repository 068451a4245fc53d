#include "insitu/enhancement.hpp"
