// horus::Loan<T>: a pool slot lent to a publisher of large data (Topic<T>::loan).
#pragma once

#include <utility>

#include "horus/shm/pool.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {

namespace detail {
template <class T>
class PooledSlots;
}  // namespace detail

/// A pool slot lent to a publisher (Topic<T>::loan): a T whose bytes are the slot itself, to be
/// filled in place and published with Topic<T>::send(std::move(loan)), which copies nothing.
/// Its bytes start with whatever the slot held before: write all of them. Dropping a loan
/// unsent gives the slot back. A loan must be sent through the handle that lent it.
template <class T>
class Loan {
 public:
  T& operator*() noexcept { return value_; }
  T* operator->() noexcept { return &value_; }
  const T& operator*() const noexcept { return value_; }
  const T* operator->() const noexcept { return &value_; }

 private:
  friend class detail::PooledSlots<T>;
  Loan(T value, const void* core, shm::Pool::Claim claim) : value_(std::move(value)), core_(core), claim_(claim) {}
  T value_;
  const void* core_;
  shm::Pool::Claim claim_;
};

}  // namespace horus

HORUS_API_END
