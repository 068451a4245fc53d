#include "parallel/distributed_config.hpp"

#include <nlohmann/json.hpp>

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
    // Listed: refused; the default list's are dropped by the Instrument, with a notice.
    const ProxySelection& proxies = config.proxies;
    const bool default_list =
        config.to_json().at("proxies") == InstrumentConfig().to_json().at("proxies");
    if (!default_list && proxies.attenuation && (proxies.interleaving || proxies.entry_depth)) {
        fail<InvalidArgument>(
            "\"proxies\": \"", proxies.interleaving ? "interleaving" : "entry_depth",
            "\" is not composited across ranks (it counts what the ray met in front of a "
            "block, which the block cannot know); leave it out of the list, or write it in a "
            "run without a communicator");
    }
    if (config.volume) {
        fail<InvalidArgument>(
            "\"volume\": a distributed run does not store the compressed field yet (each "
            "rank would write its own blocks, and only rank 0 writes); keep it in a run "
            "without a communicator");
    }
}

}  // namespace insitu
