#pragma once
// What a distributed run refuses at construction, on every rank alike: what one process of it
// cannot make (a budget's ground truth), named by its key. (Light fields composite across the
// ranks: insitu/parallel/light_field_compositing.hpp.) The interleaving counts and entry depths,
// which a block cannot count, are on in every default selection, the C++ one included, so the
// Instrument drops them with a notice.
#include "insitu/config.hpp"

namespace insitu {

/// InvalidArgument naming the first key a distributed run cannot honour.
void refuse_what_ranks_cannot_composite(const InstrumentConfig& config);

}  // namespace insitu
