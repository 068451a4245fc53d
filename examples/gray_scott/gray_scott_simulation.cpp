#include "gray_scott_simulation.hpp"

#include <algorithm>
#include <cmath>
#include <ostream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <utility>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace gray_scott {

std::ostream& operator<<(std::ostream& out, const Parameters& parameters) {
    return out << "Parameters{size=" << parameters.size << ", F=" << parameters.feed
               << ", k=" << parameters.kill << ", Du=" << parameters.diffusion_u
               << ", Dv=" << parameters.diffusion_v << ", dt=" << parameters.dt
               << ", seed=" << parameters.seed << "}";
}

std::string check(const Parameters& parameters) {
    // Feed and kill rates beyond this are far outside the pattern-forming part of the (F, k)
    // plane (which ends near F = 0.08, k = 0.07) and would break the stability budget below.
    constexpr double kMaxRate = 0.25;
    std::ostringstream message;
    const auto finite_in = [](double value, double low, double high) {
        return std::isfinite(value) && value >= low && value <= high;
    };
    if (parameters.size < 4) {
        message << "size = " << parameters.size << " (must be >= 4 samples per axis)";
    } else if (!(parameters.dt > 0.0) || !std::isfinite(parameters.dt)) {
        message << "dt = " << parameters.dt << " (must be finite and > 0)";
    } else if (!finite_in(parameters.feed, 0.0, kMaxRate)) {
        message << "F = " << parameters.feed << " (must be in [0, " << kMaxRate
                << "] per time unit)";
    } else if (!finite_in(parameters.kill, 0.0, kMaxRate)) {
        message << "k = " << parameters.kill << " (must be in [0, " << kMaxRate
                << "] per time unit)";
    } else {
        // Forward Euler amplifies the checkerboard mode once dt (12 D + r) > 2, where -12 per
        // voxel^2 is the 7-point Laplacian's most negative eigenvalue and r the reaction's own
        // damping rate: v^2 + F for u (v^2 <= 0.25 in practice), F + k for v. Capping D dt at
        // 1/8 spends 1.5 of that budget on diffusion and leaves 0.5 for dt r.
        const double limit = 1.0 / (8.0 * parameters.dt);
        const std::pair<const char*, double> diffusions[] = {{"Du", parameters.diffusion_u},
                                                             {"Dv", parameters.diffusion_v}};
        for (const auto& [name, value] : diffusions) {
            if (!finite_in(value, 0.0, limit)) {
                message << name << " = " << value << " (must be in [0, " << limit
                        << "] voxels^2 per time unit: explicit Euler with dt = " << parameters.dt
                        << " is unstable beyond about 1 / (8 dt))";
                break;
            }
        }
        const double reaction_rate =
            std::max(0.25 + parameters.feed, parameters.feed + parameters.kill);
        if (message.tellp() == 0 && parameters.dt * reaction_rate > 0.5) {
            message << "dt = " << parameters.dt << " with F = " << parameters.feed
                    << ", k = " << parameters.kill << " (dt max(0.25 + F, F + k) must be <= 0.5 "
                    << "for explicit Euler to stay stable)";
        }
    }
    return message.str();
}

int worker_threads() {
#ifdef _OPENMP
    return omp_get_max_threads();
#else
    return 1;
#endif
}

Simulation::Simulation(const Parameters& parameters) : parameters_(parameters) {
    const std::string problem = check(parameters_);
    if (!problem.empty()) throw std::invalid_argument("gray-scott: " + problem);
    const auto n = static_cast<std::size_t>(allocated_size());
    u_.assign(n * n * n, 1.0);
    v_.assign(n * n * n, 0.0);
    u_next_.resize(n * n * n);
    v_next_.resize(n * n * n);
    seed_cubes();
    fill_ghosts(u_);
    fill_ghosts(v_);
}

void Simulation::seed_cubes() {
    // A handful of cubes about an eighth of the box wide: large enough that v survives the first
    // steps (small perturbations decay back to u = 1, v = 0), few enough that the patterns have
    // room to grow into each other.
    constexpr int kCubeCount = 6;
    const int size = parameters_.size;
    const int side = std::max(3, size / 8);
    std::mt19937_64 generator(parameters_.seed);
    std::uniform_int_distribution<int> corner(0, size - 1);
    std::uniform_real_distribution<double> noise(-0.01, 0.01);
    for (int cube = 0; cube < kCubeCount; ++cube) {
        const int x0 = corner(generator);
        const int y0 = corner(generator);
        const int z0 = corner(generator);
        // Cubes wrap around the periodic box instead of being clipped at its faces.
        for (int dz = 0; dz < side; ++dz) {
            for (int dy = 0; dy < side; ++dy) {
                for (int dx = 0; dx < side; ++dx) {
                    const std::size_t at =
                        index((x0 + dx) % size + 1, (y0 + dy) % size + 1, (z0 + dz) % size + 1);
                    u_[at] = 0.5 * (1.0 + noise(generator));
                    v_[at] = 0.25 * (1.0 + noise(generator));
                }
            }
        }
    }
}

void Simulation::fill_ghosts(std::vector<double>& species) const {
    // Faces one axis after the other, each pass covering the ghosts the previous ones filled, so
    // edges and corners come out periodic too (the 7-point stencil reads only faces, but a
    // visualization reading the allocated array should never meet stale values).
    const int n = parameters_.size;
    const int all = allocated_size();
    for (int k = 1; k <= n; ++k) {
        for (int j = 1; j <= n; ++j) {
            species[index(0, j, k)] = species[index(n, j, k)];
            species[index(n + 1, j, k)] = species[index(1, j, k)];
        }
    }
    for (int k = 1; k <= n; ++k) {
        for (int i = 0; i < all; ++i) {
            species[index(i, 0, k)] = species[index(i, n, k)];
            species[index(i, n + 1, k)] = species[index(i, 1, k)];
        }
    }
    for (int j = 0; j < all; ++j) {
        for (int i = 0; i < all; ++i) {
            species[index(i, j, 0)] = species[index(i, j, n)];
            species[index(i, j, n + 1)] = species[index(i, j, 1)];
        }
    }
}

void euler_step_box(const Parameters& parameters, const double* u, const double* v, double* u_next,
                    double* v_next, int nx, int ny, int nz, std::ptrdiff_t stride_y,
                    std::ptrdiff_t stride_z) {
#pragma omp parallel for schedule(static)
    for (int k = 1; k <= nz; ++k) {
        for (int j = 1; j <= ny; ++j) {
            const std::ptrdiff_t row = k * stride_z + j * stride_y;
            for (std::ptrdiff_t at = row + 1; at <= row + nx; ++at) {
                const double u6[6] = {u[at - 1],        u[at + 1],        u[at - stride_y],
                                      u[at + stride_y], u[at - stride_z], u[at + stride_z]};
                const double v6[6] = {v[at - 1],        v[at + 1],        v[at - stride_y],
                                      v[at + stride_y], v[at - stride_z], v[at + stride_z]};
                euler_update(parameters, u[at], v[at], u6, v6, u_next[at], v_next[at]);
            }
        }
    }
}

void Simulation::step() {
    const int n = parameters_.size;
    const std::ptrdiff_t stride_y = allocated_size();
    euler_step_box(parameters_, u_.data(), v_.data(), u_next_.data(), v_next_.data(), n, n, n,
                   stride_y, stride_y * stride_y);
    std::swap(u_, u_next_);
    std::swap(v_, v_next_);
    fill_ghosts(u_);
    fill_ghosts(v_);
    ++steps_done_;
}

}  // namespace gray_scott
