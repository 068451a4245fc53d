#include "gray_scott_mpi_simulation.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

namespace gray_scott_mpi {
namespace {

/// splitmix64's output function (Steele, Lea and Flood, "Fast splittable pseudorandom number
/// generators", OOPSLA 2014): a bijective 64-bit mix, so hashing a node index cannot collide.
std::uint64_t splitmix64(std::uint64_t x) {
    x += 0x9e3779b97f4a7c15ULL;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
    return x ^ (x >> 31);
}

/// The +-1% noise of species 0 (u) or 1 (v) at global node `node`: a pure function of the seed
/// and the node, where the serial gray-scott draws it in loop order from its generator.
double noise(std::uint64_t seed, std::uint64_t node, int species) {
    const std::uint64_t bits =
        splitmix64(splitmix64(seed) ^ (2 * node + static_cast<std::uint64_t>(species)));
    const double unit = static_cast<double>(bits >> 11) * 0x1.0p-53;  // [0, 1), 53 bits
    return -0.01 + 0.02 * unit;
}

/// Global index of node (i, j, k) of a size^3 grid, x fastest.
std::uint64_t global_index(int size, int i, int j, int k) {
    const auto n = static_cast<std::uint64_t>(size);
    return (static_cast<std::uint64_t>(k) * n + static_cast<std::uint64_t>(j)) * n +
           static_cast<std::uint64_t>(i);
}

/// The seed cubes of examples/gray_scott (as many, as wide, drawn the same way from a generator
/// seeded with `seed`), which every rank draws in full, so all agree on them.
struct SeedCubes {
    int side = 0;
    std::vector<Int3> corners;

    explicit SeedCubes(const Parameters& parameters) {
        constexpr int kCubeCount = 6;
        side = std::max(3, parameters.size / 8);
        std::mt19937_64 generator(parameters.seed);
        std::uniform_int_distribution<int> corner(0, parameters.size - 1);
        for (int cube = 0; cube < kCubeCount; ++cube) {
            Int3 at{};
            for (int& coordinate : at) coordinate = corner(generator);
            corners.push_back(at);
        }
    }

    /// Whether global node `node` lies in a cube; cubes wrap around the periodic box.
    bool contain(int size, const Int3& node) const {
        return std::any_of(corners.begin(), corners.end(), [&](const Int3& corner) {
            for (int axis = 0; axis < 3; ++axis) {
                if ((node[axis] - corner[axis] + size) % size >= side) return false;
            }
            return true;
        });
    }
};

/// u = 1, v = 0 outside the cubes; u = 1/2, v = 1/4 (each +-1%) inside, as in Pearson's runs.
std::pair<double, double> initial_node(const Parameters& parameters, const SeedCubes& cubes,
                                       const Int3& node) {
    if (!cubes.contain(parameters.size, node)) return {1.0, 0.0};
    const std::uint64_t at = global_index(parameters.size, node[0], node[1], node[2]);
    return {0.5 * (1.0 + noise(parameters.seed, at, 0)),
            0.25 * (1.0 + noise(parameters.seed, at, 1))};
}

/// Throws std::invalid_argument with gray_scott::check()'s text for unusable parameters.
void require_valid(const Parameters& parameters) {
    const std::string problem = gray_scott::check(parameters);
    if (!problem.empty()) throw std::invalid_argument("gray-scott-mpi: " + problem);
}

}  // namespace

AxisRange split_axis(int size, int parts, int part) {
    const int base = size / parts;
    const int remainder = size % parts;
    return {part * base + std::min(part, remainder), base + (part < remainder ? 1 : 0)};
}

Int3 process_grid(int ranks) {
    // Cartesian dimension 0 varies slowest in the rank order; make it z, which varies slowest in
    // memory, so ranks are numbered like the nodes they hold.
    int cartesian_dims[3] = {0, 0, 0};
    MPI_Dims_create(ranks, 3, cartesian_dims);
    return {cartesian_dims[2], cartesian_dims[1], cartesian_dims[0]};
}

std::string check_decomposition(int size, int ranks) {
    const Int3 grid = process_grid(ranks);
    for (int axis = 0; axis < 3; ++axis) {
        if (size < grid[axis]) {
            return "size = " + std::to_string(size) + " is below the " +
                   std::to_string(grid[axis]) + " parts along " + "xyz"[axis] +
                   " of the process grid " + std::to_string(grid[0]) + "x" +
                   std::to_string(grid[1]) + "x" + std::to_string(grid[2]) + " of " +
                   std::to_string(ranks) + " ranks (every rank needs a node)";
        }
    }
    return {};
}

GlobalFields initial_fields(const Parameters& parameters) {
    require_valid(parameters);
    const int n = parameters.size;
    const SeedCubes cubes(parameters);
    GlobalFields fields;
    fields.size = n;
    const std::size_t count = global_index(n, 0, 0, n);
    fields.u.resize(count);
    fields.v.resize(count);
    for (int k = 0; k < n; ++k) {
        for (int j = 0; j < n; ++j) {
            for (int i = 0; i < n; ++i) {
                const std::size_t at = global_index(n, i, j, k);
                std::tie(fields.u[at], fields.v[at]) = initial_node(parameters, cubes, {i, j, k});
            }
        }
    }
    return fields;
}

GlobalFields serial_reference(const Parameters& parameters, std::int64_t steps) {
    GlobalFields fields = initial_fields(parameters);
    const int n = parameters.size;
    std::vector<double> u_next(fields.u.size());
    std::vector<double> v_next(fields.v.size());
    const auto below = [n](int i) { return i == 0 ? n - 1 : i - 1; };
    const auto above = [n](int i) { return i == n - 1 ? 0 : i + 1; };
    for (std::int64_t step = 0; step < steps; ++step) {
        const double* u = fields.u.data();
        const double* v = fields.v.data();
        for (int k = 0; k < n; ++k) {
            for (int j = 0; j < n; ++j) {
                for (int i = 0; i < n; ++i) {
                    // The neighbours in the order Simulation::step() adds them: floating-point
                    // addition is not associative, and the comparison is bit for bit.
                    const std::size_t at = global_index(n, i, j, k);
                    const std::size_t neighbours[6] = {
                        global_index(n, below(i), j, k), global_index(n, above(i), j, k),
                        global_index(n, i, below(j), k), global_index(n, i, above(j), k),
                        global_index(n, i, j, below(k)), global_index(n, i, j, above(k))};
                    double u6[6];
                    double v6[6];
                    for (int n6 = 0; n6 < 6; ++n6) {
                        u6[n6] = u[neighbours[n6]];
                        v6[n6] = v[neighbours[n6]];
                    }
                    euler_update(parameters, u[at], v[at], u6, v6, u_next[at], v_next[at]);
                }
            }
        }
        std::swap(fields.u, u_next);
        std::swap(fields.v, v_next);
    }
    return fields;
}

Simulation::Simulation(const Parameters& parameters, MPI_Comm world) : parameters_(parameters) {
    require_valid(parameters_);
    MPI_Comm_size(world, &rank_count_);
    const std::string problem = check_decomposition(parameters_.size, rank_count_);
    if (!problem.empty()) throw std::invalid_argument("gray-scott-mpi: " + problem);
    process_grid_ = gray_scott_mpi::process_grid(rank_count_);
    int cartesian_dims[3] = {process_grid_[2], process_grid_[1], process_grid_[0]};  // z, y, x
    const int periodic[3] = {1, 1, 1};
    MPI_Cart_create(world, 3, cartesian_dims, periodic, /*reorder=*/0, &cartesian_);
    MPI_Comm_rank(cartesian_, &rank_);
    int coordinates[3] = {0, 0, 0};
    MPI_Cart_coords(cartesian_, rank_, 3, coordinates);
    grid_coordinates_ = {coordinates[2], coordinates[1], coordinates[0]};
    for (int axis = 0; axis < 3; ++axis) {
        const AxisRange range =
            split_axis(parameters_.size, process_grid_[axis], grid_coordinates_[axis]);
        block_begin_[axis] = range.begin;
        block_dims_[axis] = range.count;
    }

    const Int3 all = allocated_dims();
    const std::size_t count = static_cast<std::size_t>(all[0]) * all[1] * all[2];
    u_.assign(count, 1.0);
    v_.assign(count, 0.0);
    u_next_.resize(count);
    v_next_.resize(count);
    const SeedCubes cubes(parameters_);
    for (int k = 1; k <= block_dims_[2]; ++k) {
        for (int j = 1; j <= block_dims_[1]; ++j) {
            for (int i = 1; i <= block_dims_[0]; ++i) {
                const Int3 node{block_begin_[0] + i - 1, block_begin_[1] + j - 1,
                                block_begin_[2] + k - 1};
                std::tie(u_[index(i, j, k)], v_[index(i, j, k)]) =
                    initial_node(parameters_, cubes, node);
            }
        }
    }
    make_face_types();
    exchange_halos(u_);
    exchange_halos(v_);
}

Simulation::~Simulation() {
    for (FaceTypes& face : faces_) {
        for (MPI_Datatype* type :
             {&face.first_interior, &face.last_interior, &face.low_ghost, &face.high_ghost}) {
            if (*type != MPI_DATATYPE_NULL) MPI_Type_free(type);
        }
    }
    if (cartesian_ != MPI_COMM_NULL) MPI_Comm_free(&cartesian_);
}

void Simulation::make_face_types() {
    // The slab of an axis spans the axes before it with their ghosts and the axes after it
    // without: exchanging x, then y, then z that way carries the ghosts the earlier passes filled
    // into the edges and corners (the serial gray-scott's fill_ghosts order), so a renderer
    // interpolating across a block's edge finds its diagonal neighbours' values too, at no extra
    // message.
    const Int3 all = allocated_dims();
    for (int axis = 0; axis < 3; ++axis) {
        const auto slab = [&](int position) {
            // MPI_ORDER_C lists the slowest axis first: z, y, x.
            int sizes[3];
            int subsizes[3];
            int starts[3];
            for (int other = 0; other < 3; ++other) {
                const int c = 2 - other;
                sizes[c] = all[other];
                if (other == axis) {
                    subsizes[c] = 1;
                    starts[c] = position;
                } else if (other < axis) {
                    subsizes[c] = all[other];
                    starts[c] = 0;
                } else {
                    subsizes[c] = block_dims_[other];
                    starts[c] = 1;
                }
            }
            MPI_Datatype type = MPI_DATATYPE_NULL;
            MPI_Type_create_subarray(3, sizes, subsizes, starts, MPI_ORDER_C, MPI_DOUBLE, &type);
            MPI_Type_commit(&type);
            return type;
        };
        FaceTypes& face = faces_[axis];
        face.first_interior = slab(1);
        face.last_interior = slab(block_dims_[axis]);
        face.low_ghost = slab(0);
        face.high_ghost = slab(block_dims_[axis] + 1);
        MPI_Cart_shift(cartesian_, 2 - axis, 1, &face.low_neighbour, &face.high_neighbour);
    }
}

void Simulation::exchange_halos(std::vector<double>& species) {
    const double start = MPI_Wtime();
    double* data = species.data();
    for (int axis = 0; axis < 3; ++axis) {
        const FaceTypes& face = faces_[axis];
        // Downwards: the first interior layer fills the low neighbour's high ghost while the high
        // neighbour's fills this rank's. Then upwards, the mirror image. The slabs are disjoint
        // parts of one array; with one part along the axis both neighbours are this rank.
        const int down_tag = 2 * axis;
        const int up_tag = 2 * axis + 1;
        MPI_Sendrecv(data, 1, face.first_interior, face.low_neighbour, down_tag, data, 1,
                     face.high_ghost, face.high_neighbour, down_tag, cartesian_, MPI_STATUS_IGNORE);
        MPI_Sendrecv(data, 1, face.last_interior, face.high_neighbour, up_tag, data, 1,
                     face.low_ghost, face.low_neighbour, up_tag, cartesian_, MPI_STATUS_IGNORE);
    }
    halo_seconds_ += MPI_Wtime() - start;
}

void Simulation::step() {
    const Int3 all = allocated_dims();
    // examples/gray_scott's update (euler_step_box): the same arithmetic per node is what makes
    // the result independent of the decomposition.
    euler_step_box(parameters_, u_.data(), v_.data(), u_next_.data(), v_next_.data(),
                   block_dims_[0], block_dims_[1], block_dims_[2], all[0],
                   static_cast<std::ptrdiff_t>(all[0]) * all[1]);
    std::swap(u_, u_next_);
    std::swap(v_, v_next_);
    exchange_halos(u_);
    exchange_halos(v_);
    ++steps_done_;
}

Simulation::Differences Simulation::differences_from(const GlobalFields& reference) const {
    const int n = reference.size;
    const auto wrap = [n](int node) { return (node % n + n) % n; };
    const Int3 all = allocated_dims();
    Differences differences;
    for (int k = 0; k < all[2]; ++k) {
        for (int j = 0; j < all[1]; ++j) {
            for (int i = 0; i < all[0]; ++i) {
                const std::size_t at = index(i, j, k);
                const std::size_t global =
                    global_index(n, wrap(block_begin_[0] + i - 1), wrap(block_begin_[1] + j - 1),
                                 wrap(block_begin_[2] + k - 1));
                ++differences.compared;
                // memcmp: bit for bit, so even +0 against -0 would count.
                if (std::memcmp(&u_[at], &reference.u[global], sizeof(double)) == 0 &&
                    std::memcmp(&v_[at], &reference.v[global], sizeof(double)) == 0) {
                    continue;
                }
                ++differences.nodes;
                differences.largest =
                    std::max({differences.largest, std::abs(u_[at] - reference.u[global]),
                              std::abs(v_[at] - reference.v[global])});
            }
        }
    }
    return differences;
}

std::uint64_t Simulation::checksum() const {
    std::uint64_t sum = 0;
    for (int k = 1; k <= block_dims_[2]; ++k) {
        for (int j = 1; j <= block_dims_[1]; ++j) {
            for (int i = 1; i <= block_dims_[0]; ++i) {
                std::uint64_t u_bits = 0;
                std::uint64_t v_bits = 0;
                std::memcpy(&u_bits, &u_[index(i, j, k)], sizeof u_bits);
                std::memcpy(&v_bits, &v_[index(i, j, k)], sizeof v_bits);
                const std::uint64_t node =
                    global_index(parameters_.size, block_begin_[0] + i - 1, block_begin_[1] + j - 1,
                                 block_begin_[2] + k - 1);
                sum += splitmix64(node ^ splitmix64(u_bits ^ splitmix64(v_bits)));
            }
        }
    }
    std::uint64_t total = 0;
    MPI_Allreduce(&sum, &total, 1, MPI_UINT64_T, MPI_SUM, cartesian_);
    return total;
}

}  // namespace gray_scott_mpi
