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
    if (config.light_field) {
        fail<InvalidArgument>(
            "\"light_field\": light fields are not composited across ranks (their segments "
            "and first hits depend on the opacity in front of a block, which the block "
            "cannot know); capture them in a run without a communicator");
    }
}

}  // namespace insitu
