#pragma once
// Checks of the library's own invariants (pbrt-v4's util/check.h is the model): a failed check
// is a bug in libinsitu, not bad input, so it says which expression failed, where, and the
// values of both sides. User input is validated with typed errors (insitu/error.hpp) instead.
//
//   INSITU_CHECK(cond)          always on
//   INSITU_CHECK_EQ(a, b)       always on; also _NE, _LT, _LE, _GT, _GE; prints a and b
//   INSITU_DCHECK...(...)       the same, compiled out with NDEBUG (hot loops)
//
// A failed check throws InvariantError (an insitu::Error): the Instrument and the C API turn it
// into a status like every other error, so a libinsitu bug never terminates the simulation.
#include <sstream>
#include <string>

#include "insitu/error.hpp"

namespace insitu {

/// A broken internal invariant (a libinsitu bug), with the expression, location and values.
class InvariantError : public Error {
public:
    using Error::Error;
};

namespace detail {

template <typename A, typename B>
[[noreturn]] void fail_check(const char* file, int line, const char* expression, const A& a,
                             const B& b) {
    std::ostringstream out;
    out << file << ":" << line << ": check failed: " << expression << " with " << a << " vs " << b;
    throw InvariantError(out.str());
}

[[noreturn]] inline void fail_check(const char* file, int line, const char* expression) {
    std::ostringstream out;
    out << file << ":" << line << ": check failed: " << expression;
    throw InvariantError(out.str());
}

}  // namespace detail
}  // namespace insitu

#define INSITU_CHECK(condition)                                                         \
    do {                                                                                \
        if (!(condition)) ::insitu::detail::fail_check(__FILE__, __LINE__, #condition); \
    } while (false)

// Both sides are evaluated once; their values are printed on failure.
#define INSITU_CHECK_OP(a, op, b)                                                               \
    do {                                                                                        \
        const auto& insitu_check_a = (a);                                                       \
        const auto& insitu_check_b = (b);                                                       \
        if (!(insitu_check_a op insitu_check_b)) {                                              \
            ::insitu::detail::fail_check(__FILE__, __LINE__, #a " " #op " " #b, insitu_check_a, \
                                         insitu_check_b);                                       \
        }                                                                                       \
    } while (false)

#define INSITU_CHECK_EQ(a, b) INSITU_CHECK_OP(a, ==, b)
#define INSITU_CHECK_NE(a, b) INSITU_CHECK_OP(a, !=, b)
#define INSITU_CHECK_LT(a, b) INSITU_CHECK_OP(a, <, b)
#define INSITU_CHECK_LE(a, b) INSITU_CHECK_OP(a, <=, b)
#define INSITU_CHECK_GT(a, b) INSITU_CHECK_OP(a, >, b)
#define INSITU_CHECK_GE(a, b) INSITU_CHECK_OP(a, >=, b)

#ifdef NDEBUG
// Compiled out, but the expressions still parse (and name no unused variables).
#define INSITU_DCHECK(condition)      \
    do {                              \
        if (false) (void)(condition); \
    } while (false)
#define INSITU_DCHECK_OP(a, op, b)   \
    do {                             \
        if (false) (void)((a)op(b)); \
    } while (false)
#else
#define INSITU_DCHECK(condition) INSITU_CHECK(condition)
#define INSITU_DCHECK_OP(a, op, b) INSITU_CHECK_OP(a, op, b)
#endif
#define INSITU_DCHECK_EQ(a, b) INSITU_DCHECK_OP(a, ==, b)
#define INSITU_DCHECK_NE(a, b) INSITU_DCHECK_OP(a, !=, b)
#define INSITU_DCHECK_LT(a, b) INSITU_DCHECK_OP(a, <, b)
#define INSITU_DCHECK_LE(a, b) INSITU_DCHECK_OP(a, <=, b)
#define INSITU_DCHECK_GT(a, b) INSITU_DCHECK_OP(a, >, b)
#define INSITU_DCHECK_GE(a, b) INSITU_DCHECK_OP(a, >=, b)
