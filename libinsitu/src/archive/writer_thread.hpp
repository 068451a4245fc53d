#pragma once
// The archive writer thread's claim on the CPU (issue 18, item 10). An MPI launcher binds a rank
// to one core, and the writer thread (EXR and PNG encoding, file writes) runs on that core too: at
// the simulation's own priority it takes half the core whenever it has work, so the simulation
// slows down by more than the time it spends inside execute(). At the lowest priority the writer
// runs only when the core would otherwise be idle: while the simulation waits in execute()
// (blocked on a full queue, timed in blocked_seconds) or in finalize(), or on a spare core.
// The cost moves, it does not vanish: on a core the simulation keeps busy, "when_full": "block"
// waits in execute() for the writer, and "when_full": "drop" drops the steps it cannot keep up
// with. Linux derives an unset I/O priority from the policy: the writer's file I/O goes to the
// idle class where the disk scheduler honours classes (BFQ, mq-deadline); "none", the usual NVMe
// default, and a parallel file system's network I/O do not.

namespace insitu::archive_format {

/// Lowers the calling thread's scheduling priority to the lowest the system offers; call it from
/// the writer thread itself. Linux: SCHED_IDLE, or nice 19 where a policy change is refused.
/// Returns whether the priority was lowered (false elsewhere, or when both are refused: the
/// thread then keeps its priority, which costs time but loses nothing). Never throws.
bool lower_writer_thread_priority() noexcept;

}  // namespace insitu::archive_format
