// The process context: what horus keeps once per process and that no layer may keep on its own.
//
//   - the settings snapshot: the environment variables horus reads (Environment), read here and
//     nowhere else. It is read on first use and again only when the process has changed its
//     environment since (setenv, unsetenv, putenv of a new string): a program sets its variables
//     before its first topic, a test may change them between two topics. The layers take their
//     values from it, or as parameters from the one that took it;
//   - the fork rules: one pthread_atfork for the library, which runs the handlers the layers
//     register (at_fork) in a fixed order, and the two facts a forked child must not inherit (its
//     pid, and how many forks lie between it and the first process);
//   - the parts: what a layer keeps once per process (the open topics, the transports, the
//     network engines, the fleet agents, the caches). A layer declares its part (a type with a
//     PartSpec: its name, its lifetime and why) and reaches it with part<T>(); the context makes
//     it on first use and ends it at exit in the one order written down here: the reverse order
//     of the parts' making, or never for a part something may still need while the process's
//     statics end. parts() lists them (docs/ARCHITECTURE.md's table is checked against it).
//
// Not public API.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string_view>
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

/// How long a part of the context lives.
enum class PartLifetime : std::uint8_t {
  UntilExit,  // ended at exit (after main returns), in the reverse order of the parts' making
  Process,    // never ended: something may still use it while the process's statics end
};

/// What a part is (a type's `static constexpr PartSpec kPart`): its name (one part per name and
/// process, whichever library of the process asks first makes it), its lifetime, and why.
struct PartSpec {
  std::string_view name;
  PartLifetime lifetime;
  std::string_view why;
};

/// A part the context made, as parts() lists them.
struct PartRecord {
  PartSpec spec;
  bool ended = false;
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

  /// The process's part T (T::kPart a PartSpec, T default-constructible), made on first use.
  template <class T>
  static T& part() {
    static T* const p = static_cast<T*>(
        get().find_or_make(T::kPart, []() -> void* { return new T(); }, [](void* q) noexcept { delete static_cast<T*>(q); }));
    return *p;
  }
  /// The parts made so far, in the order of their making.
  std::vector<PartRecord> parts() const;

  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;

 private:
  Process();
  ~Process() = default;
  static void prepare_fork() noexcept;
  static void after_fork_in_parent() noexcept;
  static void after_fork_in_child() noexcept;
  void* find_or_make(const PartSpec& spec, void* (*make)(), void (*end)(void*) noexcept);
  static void end_last_part() noexcept;  // one atexit call per part that ends at exit

  mutable std::mutex settings_mutex_;
  std::shared_ptr<const Environment> environment_;
  std::uint64_t environment_print_ = 0;
  std::uint64_t environment_reads_ = 0;
  std::mutex fork_mutex_;  // held from prepare to parent/child: no registration during a fork
  std::vector<ForkHandlers> fork_handlers_;
  struct Part {
    PartRecord record;
    void* object;
    void (*end)(void*) noexcept;
  };
  // Recursive: a part's constructor may ask for another part (made first, so ended after it).
  mutable std::recursive_mutex parts_mutex_;
  std::vector<Part> parts_;
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
