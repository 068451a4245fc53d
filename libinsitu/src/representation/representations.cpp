// The registry of representations: adding one is a folder beside these and a line here.
#include "representation/light_field/light_field_representation.hpp"
#include "representation/representation.hpp"
#include "representation/view_proxies/view_proxies.hpp"
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
