#include "archive/writer_thread.hpp"

#if defined(__linux__)
#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

namespace insitu::archive_format {

bool lower_writer_thread_priority() noexcept {
#if defined(__linux__)
    // SCHED_IDLE: the fair scheduler's smallest weight, below nice 19, so a runnable simulation
    // thread on the same core always goes first; lowering a thread's own policy needs no
    // privilege. On one pinned core the writer at the simulation's priority slowed the
    // simulation's own steps markedly, at SCHED_IDLE hardly (bench/RESULTS.md, "The archive
    // writer's thread at SCHED_IDLE"), and the overhead it sees is then the time inside
    // execute() and finalize().
    sched_param parameters{};
    parameters.sched_priority = 0;  // the only value SCHED_IDLE takes
    if (pthread_setschedparam(pthread_self(), SCHED_IDLE, &parameters) == 0) return true;
    // A kernel or sandbox that refuses the policy: nice 19 is the next lowest, per thread on
    // Linux (setpriority with a thread id).
    const auto thread = static_cast<id_t>(syscall(SYS_gettid));
    return setpriority(PRIO_PROCESS, thread, 19) == 0;
#else
    return false;
#endif
}

}  // namespace insitu::archive_format
