// The process context: what horus keeps once per process and that no layer may keep on its own.
//
//   - the settings snapshot: the environment variables horus reads (Environment), read here and
//     nowhere else. It is read on first use and again only when the process has changed its
//     environment since (setenv, unsetenv, putenv of a new string): a program sets its variables
//     before its first topic, a test may change them between two topics. The layers take their
//     values from it, or as parameters from the one that took it;
//   - the fork rules: one pthread_atfork for the library, which runs the handlers the layers
//     register (at_fork) in a fixed order, and the two facts a forked child must not inherit (its
//     pid, and how many forks lie between it and the first process).
//
// What remains process-wide outside this object (the registries of the layers above core, whose
// types core cannot name) is listed in docs/ARCHITECTURE.md with why and in which order it ends.
// Not public API.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "horus/environment.hpp"
#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::detail {

/// One layer's part in fork(): prepare runs in the parent before the fork (it takes the locks a
/// child must not find held), parent and child after it in each process (they release them).
/// Any of the three may be null.
struct ForkHandlers {
  void (*prepare)() = nullptr;
  void (*parent)() = nullptr;
  void (*child)() = nullptr;
};

class Process {
 public:
  /// The process's context, made on first use. Never destroyed: destructors of other statics
  /// (a topic closed during static destruction) may still read it.
  static Process& get() noexcept;

  /// The settings snapshot (see above). The same object while the environment is unchanged.
  std::shared_ptr<const Environment> environment();
  /// How many snapshots were taken (1 after the first environment() call): a test's witness.
  std::uint64_t environment_reads() const;

  /// Registers a layer's fork handlers. Prepare handlers run in the reverse order of registration,
  /// parent and child handlers in the order of registration (pthread_atfork's rule), after the
  /// context's own: a child's pid and fork generation are right before any child handler runs.
  void at_fork(ForkHandlers handlers);

  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;

 private:
  Process();
  ~Process() = default;
  static void prepare_fork() noexcept;
  static void after_fork_in_parent() noexcept;
  static void after_fork_in_child() noexcept;

  mutable std::mutex settings_mutex_;
  std::shared_ptr<const Environment> environment_;
  std::uint64_t environment_print_ = 0;
  std::uint64_t environment_reads_ = 0;
  std::mutex fork_mutex_;  // held from prepare to parent/child: no registration during a fork
  std::vector<ForkHandlers> fork_handlers_;
};

/// This process's pid, right in a forked child (getpid() without a system call per use).
extern std::atomic<int> g_process_pid;
/// How many fork()s lie between the first process and this one: a forked child's copy of a state
/// that names the parent's generation knows it is not its own.
extern std::atomic<std::uint32_t> g_fork_generation;

inline int current_pid() noexcept {
  const int pid = g_process_pid.load(std::memory_order_relaxed);
  if (pid != 0) [[likely]]
    return pid;
  (void)Process::get();  // sets it
  return g_process_pid.load(std::memory_order_relaxed);
}

inline std::uint32_t fork_generation() noexcept { return g_fork_generation.load(std::memory_order_relaxed); }

}  // namespace horus::detail

HORUS_API_END
