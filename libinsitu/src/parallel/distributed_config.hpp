#pragma once
// What a distributed run refuses at construction, on every rank alike: what one process of it
// cannot make (a budget's ground truth, light fields, the compressed field, the interleaving
// counts and entry depths a block cannot count), each named by its key.
#include "insitu/config.hpp"

namespace insitu {

/// InvalidArgument naming the first key a distributed run cannot honour.
void refuse_what_ranks_cannot_composite(const InstrumentConfig& config);

}  // namespace insitu
