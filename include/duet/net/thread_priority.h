// Scheduling priority of the live loop's thread. On a machine busy with other work (compilers,
// a browser, a game engine) a thread that sleeps until the next frame may wake milliseconds late:
// the scheduler lets the running task finish its slice. A real-time policy (SCHED_FIFO, low
// priority) makes the loop's thread run as soon as its frame arrives; it uses a few percent of a
// core at 120 Hz, and the kernel's real-time throttling keeps the rest of the system alive if it
// ever misbehaves. Linux only; elsewhere these do nothing.
#pragma once

#include <string>

namespace duet::net {

// Tries SCHED_FIFO (priority 10) for the calling thread, else a nice value of -10, else leaves it.
// Returns what was applied, for a log line.
std::string raise_thread_priority();

// Back to the normal policy for the calling thread: threads inherit their creator's policy, and
// helper threads started from the loop (model building, file work) must not compete with it.
void use_normal_priority();

}  // namespace duet::net
