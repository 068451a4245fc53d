#include "parallel/distributed_config.hpp"

#include "insitu/error.hpp"

namespace insitu {

void refuse_what_ranks_cannot_composite(const InstrumentConfig& config) {
    if (config.budget) {
        fail<InvalidArgument>(
            "\"budget\": an error budget is measured against a ground truth of the whole "
            "field, which one process of a distributed run does not hold; give the settings "
            "themselves, or measure them in a run without a communicator");
    }
}

}  // namespace insitu
