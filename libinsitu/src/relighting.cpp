#include "insitu/relighting.hpp"
