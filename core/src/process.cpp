#include "horus/detail/process.hpp"

#include <pthread.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>

extern char** environ;

namespace horus::detail {

std::atomic<int> g_process_pid{0};
std::atomic<std::uint32_t> g_fork_generation{0};

namespace {

// What the process's environment is now, in a few dozen loads: the array, its length and its
// entries' addresses. setenv and putenv store a new entry (a new address) and unsetenv shifts the
// array, so a change of any variable changes this; only a program that writes into the text of
// an entry it gave putenv goes unseen (horus then keeps the values it read).
std::uint64_t environment_print() noexcept {
  std::uint64_t h = 0x9e3779b97f4a7c15ull ^ reinterpret_cast<std::uintptr_t>(environ);
  std::size_t n = 0;
  if (environ != nullptr) {
    for (char** e = environ; *e != nullptr; ++e, ++n) {
      h ^= reinterpret_cast<std::uintptr_t>(*e);
      h *= 0x100000001b3ull;
      h ^= h >> 29;
    }
  }
  return h ^ (n * 0xff51afd7ed558ccdull);
}

// Made while the library loads (before main), as the fork handler it registers must be: a state
// that records fork_generation() must see every later fork counted.
[[maybe_unused]] const bool g_made_at_load = (Process::get(), true);

}  // namespace

Process& Process::get() noexcept {
  static Process* const process = new Process();  // never destroyed (see the header)
  return *process;
}

Process::Process() {
  g_process_pid.store(static_cast<int>(::getpid()), std::memory_order_relaxed);
  ::pthread_atfork(&Process::prepare_fork, &Process::after_fork_in_parent, &Process::after_fork_in_child);
}

std::shared_ptr<const Environment> Process::environment() {
  const std::uint64_t print = environment_print();
  std::lock_guard lock(settings_mutex_);
  if (!environment_ || print != environment_print_) {
    environment_ = std::make_shared<const Environment>(Environment::read());
    environment_print_ = print;
    ++environment_reads_;
  }
  return environment_;
}

std::uint64_t Process::environment_reads() const {
  std::lock_guard lock(settings_mutex_);
  return environment_reads_;
}

void* Process::find_or_make(const PartSpec& spec, void* (*make)(), void (*end)(void*) noexcept) {
  std::lock_guard lock(parts_mutex_);
  for (const Part& p : parts_)
    if (p.record.spec.name == spec.name) return p.object;
  void* object = make();
  parts_.push_back({{spec, false}, object, end});
  // atexit runs its functions in the reverse order of their registration, between the
  // destructors of the statics made before and after: the part ends where a function-local
  // static made at this moment would.
  if (spec.lifetime == PartLifetime::UntilExit) std::atexit(&Process::end_last_part);
  return object;
}

void Process::end_last_part() noexcept {
  Process& p = get();
  void* object = nullptr;
  void (*end)(void*) noexcept = nullptr;
  {
    std::lock_guard lock(p.parts_mutex_);
    for (auto it = p.parts_.rbegin(); it != p.parts_.rend(); ++it) {
      if (it->record.spec.lifetime != PartLifetime::UntilExit || it->record.ended) continue;
      it->record.ended = true;
      object = it->object;
      end = it->end;
      break;
    }
  }
  if (end != nullptr) end(object);  // outside the lock: a part's destructor may use other parts
}

std::vector<PartRecord> Process::parts() const {
  std::lock_guard lock(parts_mutex_);
  std::vector<PartRecord> out;
  out.reserve(parts_.size());
  for (const Part& p : parts_) out.push_back(p.record);
  return out;
}

void Process::at_fork(ForkHandlers handlers) {
  std::lock_guard lock(fork_mutex_);
  fork_handlers_.push_back(handlers);
}

void Process::prepare_fork() noexcept {
  Process& p = get();
  p.fork_mutex_.lock();  // released by the parent and child handlers below
  for (auto it = p.fork_handlers_.rbegin(); it != p.fork_handlers_.rend(); ++it)
    if (it->prepare != nullptr) it->prepare();
  p.settings_mutex_.lock();  // a child finds the snapshot free
}

void Process::after_fork_in_parent() noexcept {
  Process& p = get();
  p.settings_mutex_.unlock();
  for (const ForkHandlers& h : p.fork_handlers_)
    if (h.parent != nullptr) h.parent();
  p.fork_mutex_.unlock();
}

void Process::after_fork_in_child() noexcept {
  Process& p = get();
  g_process_pid.store(static_cast<int>(::getpid()), std::memory_order_relaxed);
  g_fork_generation.fetch_add(1, std::memory_order_relaxed);
  p.settings_mutex_.unlock();
  for (const ForkHandlers& h : p.fork_handlers_)
    if (h.child != nullptr) h.child();
  p.fork_mutex_.unlock();
}

}  // namespace horus::detail
