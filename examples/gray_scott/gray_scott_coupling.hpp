#pragma once
// What gray-scott and gray-scott-mpi share of their coupling to libinsitu: the command-line
// overrides of the configuration, the configuration without --config and field v's transfer
// function. (gray_scott_simulation.hpp, the simulation, knows nothing of libinsitu.)
#include <cstdint>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "cli.hpp"
#include "insitu/config.hpp"
#include "insitu/core/transfer_function.hpp"
#include "insitu/error.hpp"

namespace gray_scott {

/// The options that couple a run to libinsitu, set only when given, so that they override a
/// configuration file and nothing else.
struct CouplingOptions {
    std::optional<std::string> config_path;
    std::optional<std::string> archive;
    std::optional<std::int64_t> every;
    std::optional<int> image_width;
    std::optional<int> image_height;
    std::optional<double> azimuth_deg;
    std::optional<double> elevation_deg;
};

/// v is 0 in the trivial state (u = 1, v = 0) that fills most of the box and rises to about 0.45
/// inside the patterns. Up to 0.12 (background and the thin diffusion halo around patterns) stays
/// transparent, so the structures are seen rather than a fog; above it opacity and colour climb
/// together, blue at the fringes to warm yellow in the cores. Opacity is per voxel
/// (unit_length = 1 world unit = 1 voxel) and kept at or below 0.4: v changes by up to 0.1 per
/// voxel across a front, and a steeper function shows the sampling as wood-grain rings.
inline insitu::TransferFunction v_transfer_function() {
    return insitu::TransferFunction(
        {
            {0.00, {0.10f, 0.25f, 0.75f, 0.00f}},
            {0.12, {0.10f, 0.25f, 0.75f, 0.00f}},
            {0.20, {0.15f, 0.55f, 0.90f, 0.04f}},
            {0.28, {0.35f, 0.85f, 0.70f, 0.10f}},
            {0.36, {0.95f, 0.80f, 0.30f, 0.22f}},
            {0.45, {1.00f, 0.40f, 0.15f, 0.40f}},
        },
        /*unit_length=*/1.0);
}

/// The configuration without --config: field v seen from one orbit view, gray-scott's transfer
/// function, layers and intervals chosen from the data (the library's defaults), archived as
/// `archive`.
inline insitu::InstrumentConfig default_config(const std::string& archive) {
    insitu::InstrumentConfig config;
    config.fields = {"v"};
    config.views[0].orbit.width = 256;
    config.views[0].orbit.height = 256;
    config.transfer_function = v_transfer_function();
    // Half-voxel steps: at one voxel the fronts show sampling rings (checked by eye at 64^3; a
    // quarter voxel looks the same as a half and costs twice as much).
    config.step_voxels = 0.5;
    config.every = 50;
    config.archive = archive;
    return config;
}

/// The configuration file (or default_config(default_archive)) with the command line's
/// overrides applied and validated. A warning about unknown keys goes to stderr as `program`'s
/// when `report_warnings` (a typo is an error unless the file says "strict": false). Throws
/// insitu::cli::UsageError naming the file or the value.
inline insitu::InstrumentConfig make_config(const CouplingOptions& options,
                                            const std::string& default_archive,
                                            const std::string& program, bool report_warnings) {
    using insitu::cli::UsageError;
    insitu::InstrumentConfig config;
    if (options.config_path) {
        std::vector<std::string> unknown;
        std::string warning;
        try {
            config = insitu::InstrumentConfig::from_json_file(*options.config_path, &unknown);
            warning = insitu::refuse_unknown_keys(config, unknown, *options.config_path + ": ");
        } catch (const insitu::Error& error) {
            throw UsageError(std::string("--config: ") + error.what());  // names the file
        }
        if (!warning.empty() && report_warnings) {
            std::cerr << program << ": warning: " << warning << std::endl;
        }
    } else {
        config = default_config(default_archive);
    }
    if (options.archive) config.archive = *options.archive;
    if (options.every) {
        config.every = *options.every;
        config.steps.clear();
    }
    for (insitu::ViewConfig& view : config.views) {
        if (options.image_width) view.orbit.width = *options.image_width;
        if (options.image_height) view.orbit.height = *options.image_height;
        if (options.azimuth_deg) view.orbit.azimuth_deg = *options.azimuth_deg;
        if (options.elevation_deg) view.orbit.elevation_deg = *options.elevation_deg;
    }
    try {
        config.validate();
    } catch (const insitu::Error& error) {
        throw UsageError(error.what());
    }
    return config;
}

}  // namespace gray_scott
