#pragma once
// The Gray-Scott simulation's v field copied into a SampledVolume (interior only, x fastest), for
// benchmarks that need a real simulation field as a volume they own (the simulation keeps
// stepping, the copy stays).
#include <cstddef>

#include "gray_scott_simulation.hpp"
#include "insitu/testing/analytic_fields.hpp"

namespace insitu::bench {

inline SampledVolume gray_scott_volume(const gray_scott::Simulation& simulation) {
    const int size = simulation.size();
    SampledVolume volume;
    volume.name = "v";
    volume.dims = {size, size, size};
    volume.values.resize(static_cast<std::size_t>(size) * size * size);
    std::size_t index = 0;
    for (int k = 0; k < size; ++k) {
        for (int j = 0; j < size; ++j) {
            for (int i = 0; i < size; ++i) {
                volume.values[index++] = static_cast<float>(simulation.v(i, j, k));
            }
        }
    }
    return volume;
}

}  // namespace insitu::bench
