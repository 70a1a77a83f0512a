#include "duet/net/thread_priority.h"

#include <cerrno>
#include <cstring>

#if defined(__linux__)
#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

namespace duet::net {

std::string raise_thread_priority() {
#if defined(__linux__)
  sched_param param{};
  param.sched_priority = 10;
  const int fifo = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
  if (fifo == 0) return "real-time scheduling (SCHED_FIFO, priority 10)";
  // Nice values are per thread on Linux.
  const auto tid = static_cast<id_t>(::syscall(SYS_gettid));
  if (::setpriority(PRIO_PROCESS, tid, -10) == 0) {
    return std::string("nice -10 (no permission for real-time scheduling: ") + std::strerror(fifo) +
           ")";
  }
  return std::string("normal priority (no permission to raise it: ") + std::strerror(fifo) +
         "); latency may suffer on a busy machine";
#else
  return "normal priority (raising it is implemented for Linux only)";
#endif
}

void use_normal_priority() {
#if defined(__linux__)
  int policy = SCHED_OTHER;
  sched_param param{};
  if (pthread_getschedparam(pthread_self(), &policy, &param) == 0 && policy != SCHED_OTHER) {
    param.sched_priority = 0;
    pthread_setschedparam(pthread_self(), SCHED_OTHER, &param);
  }
  const auto tid = static_cast<id_t>(::syscall(SYS_gettid));
  errno = 0;
  const int nice = ::getpriority(PRIO_PROCESS, tid);
  if (errno == 0 && nice < 0) ::setpriority(PRIO_PROCESS, tid, 0);
#endif
}

}  // namespace duet::net
