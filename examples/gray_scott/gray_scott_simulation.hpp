#pragma once
// A 3D Gray-Scott reaction-diffusion simulation, the kind of code libinsitu couples to.
//
//   du/dt = Du lap(u) - u v^2 + F (1 - u)
//   dv/dt = Dv lap(v) + u v^2 - (F + k) v
//
// Explicit Euler in time, the 7-point Laplacian on a grid of spacing 1 (one voxel = one length
// unit), periodic boundaries. Like most stencil codes it stores each species with one ghost layer
// per side, (size + 2)^3 doubles, x fastest; the ghosts are refilled from the opposite faces after
// every step, so the arrays are always complete and a visualization can view the interior
// without a copy (Field::set_ghost_layers(1)).
//
// This file knows nothing about libinsitu on purpose: the coupling lives in gray_scott_main.cpp.
#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

namespace gray_scott {

struct Parameters {
    /// Interior samples per axis (>= 4).
    int size = 64;
    /// Feed rate of u and kill rate of v, per time unit. F = 0.025, k = 0.055 (with Du = 2 Dv)
    /// lies in the pattern-forming band of Pearson's (1993) (F, k) map; in 3D the seed cubes grow
    /// into shells that meet and break up into sheets and spots (checked by eye at 64^3 and
    /// 96^3) instead of dying out or turning the box uniform.
    double feed = 0.025;
    double kill = 0.055;
    /// Diffusion coefficients in voxels^2 per time unit. Pearson's 2D runs use about 0.2 and 0.1
    /// per step. Explicit Euler on the 3D 7-point Laplacian (eigenvalues down to -12 / h^2) plus
    /// the reaction's own damping of u (rate v^2 + F, up to about 0.3) needs
    /// dt (12 Du + v^2 + F) <= 2; at Du = 0.16, dt = 1 that fails and u grows a checkerboard.
    /// 0.12 and 0.06 keep the 2:1 ratio (which, with F and k, sets the pattern type; the absolute
    /// value only sets the pattern wavelength, here 0.77 of Pearson's) with margin to spare.
    double diffusion_u = 0.12;
    double diffusion_v = 0.06;
    /// Time step in time units.
    double dt = 1.0;
    /// Seed of the random seed cubes and of the 1% noise that breaks their symmetry.
    std::uint64_t seed = 1;
};

std::ostream& operator<<(std::ostream& out, const Parameters& parameters);

/// Checks `parameters`; returns an empty string when they are usable, otherwise one line naming
/// the offending parameter and value (the CLI prints it, the simulation throws it).
std::string check(const Parameters& parameters);

/// One explicit Euler step of one node from its values and its six neighbours' in the order -x,
/// +x, -y, +y, -z, +z: the one definition of the update, which examples/gray_scott_mpi shares, so
/// that a decomposed run adds in the same order (floating-point addition is not associative) and
/// agrees with this one bit for bit.
inline void euler_update(const Parameters& parameters, double u, double v, const double (&u6)[6],
                         const double (&v6)[6], double& u_next, double& v_next) {
    const double laplacian_u = u6[0] + u6[1] + u6[2] + u6[3] + u6[4] + u6[5] - 6.0 * u;
    const double laplacian_v = v6[0] + v6[1] + v6[2] + v6[3] + v6[4] + v6[5] - 6.0 * v;
    const double reaction = u * v * v;
    const double dt = parameters.dt;
    u_next =
        u + dt * (parameters.diffusion_u * laplacian_u - reaction + parameters.feed * (1.0 - u));
    v_next = v + dt * (parameters.diffusion_v * laplacian_v + reaction -
                       (parameters.feed + parameters.kill) * v);
}

/// euler_update of every interior node of a box of nx x ny x nz nodes stored with one ghost layer
/// per side (x fastest, strides in nodes), into u_next, v_next; parallel over z slices (OpenMP):
/// each node reads only the current arrays, so the result does not depend on the thread count.
void euler_step_box(const Parameters& parameters, const double* u, const double* v, double* u_next,
                    double* v_next, int nx, int ny, int nz, std::ptrdiff_t stride_y,
                    std::ptrdiff_t stride_z);

/// Threads Simulation::step() runs on: OpenMP's maximum, or 1 in a build without OpenMP.
int worker_threads();

class Simulation {
public:
    /// Sets u = 1, v = 0 everywhere, then seeds a few random cubes with u = 1/2, v = 1/4 (plus
    /// +-1% noise), as in Pearson's experiments. Throws std::invalid_argument with check()'s text.
    explicit Simulation(const Parameters& parameters);

    /// One explicit Euler step of dt, parallel over z slices (OpenMP when built with it), then
    /// the periodic ghost refill.
    void step();

    const Parameters& parameters() const { return parameters_; }
    /// Steps taken since construction.
    std::int64_t steps_done() const { return steps_done_; }
    /// Interior samples per axis.
    int size() const { return parameters_.size; }
    /// Samples per axis including the ghost layers: size() + 2.
    int allocated_size() const { return parameters_.size + 2; }

    /// The current arrays including ghosts: allocated_size()^3 doubles, x fastest. The pointers
    /// change with every step (the update writes into a second buffer and swaps).
    const double* u_data() const { return u_.data(); }
    const double* v_data() const { return v_.data(); }

    /// Interior sample (i, j, k), 0 <= i, j, k < size(); no bounds check.
    double u(int i, int j, int k) const { return u_[index(i + 1, j + 1, k + 1)]; }
    double v(int i, int j, int k) const { return v_[index(i + 1, j + 1, k + 1)]; }

private:
    /// Offset of allocated sample (i, j, k), ghosts included (0 <= i, j, k < allocated_size()).
    std::size_t index(int i, int j, int k) const {
        const std::size_t n = static_cast<std::size_t>(allocated_size());
        return (static_cast<std::size_t>(k) * n + static_cast<std::size_t>(j)) * n +
               static_cast<std::size_t>(i);
    }
    void seed_cubes();
    void fill_ghosts(std::vector<double>& species) const;

    Parameters parameters_;
    std::vector<double> u_;
    std::vector<double> v_;
    std::vector<double> u_next_;
    std::vector<double> v_next_;
    std::int64_t steps_done_ = 0;
};

}  // namespace gray_scott
