#include "insitu/transfer_function_edit.hpp"
