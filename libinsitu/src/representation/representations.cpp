// The registry of representations: adding one is a folder beside these and a line here (and,
// where it stores files of its own, a line in entry_lists).
#include "archive/entry_list.hpp"
#include "representation/light_field/light_field_entries.hpp"
#include "representation/light_field/light_field_representation.hpp"
#include "representation/representation.hpp"
#include "representation/view_proxies/view_proxies.hpp"
#include "representation/volume/volume_entries.hpp"
#include "representation/volume/volume_representation.hpp"

namespace insitu {

const std::vector<std::unique_ptr<Representation>>& representations() {
    static const std::vector<std::unique_ptr<Representation>> registered = [] {
        std::vector<std::unique_ptr<Representation>> all;
        all.push_back(std::make_unique<ViewProxies>());
        // The compressed field before the light field: where the budget keeps it, the light
        // field is not needed.
        all.push_back(std::make_unique<VolumeRepresentation>());
        all.push_back(std::make_unique<LightFieldRepresentation>());
        return all;
    }();
    return registered;
}

}  // namespace insitu

namespace insitu::archive_format {

const std::vector<const EntryList*>& entry_lists() {
    // The views' proxies and previews are the step entry's "views", not a list of these.
    static const std::vector<const EntryList*> registered{&light_field_entry_list(),
                                                          &volume_entry_list()};
    return registered;
}

}  // namespace insitu::archive_format
