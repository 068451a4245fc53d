#include "insitu/explorer.hpp"
