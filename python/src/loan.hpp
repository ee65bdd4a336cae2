// horus.Loan: a pool slot lent by Topic.loan() for a large-data message, filled in place
// through Loan.data (a writable NumPy view of the slot) and published by Topic.send(loan),
// which copies nothing. After the send the slot belongs to the subscribers: the arrays taken
// from Loan.data turn read-only (writing raises), and the loan is empty. The loan keeps the
// handle that lent it open, so the memory stays mapped while such an array lives (reading it
// never crashes, even after Topic.close()),
// but what it shows after the send is whatever the pool puts in the slot next; views made
// from those arrays before the send (a[0], slices) cannot be revoked by NumPy: do not write
// through them after sending.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <memory>
#include <utility>
#include <vector>

#include "horus/loan.hpp"
#include "large_data.hpp"

namespace horus::python {

namespace py = pybind11;

struct LoanBase {
  virtual ~LoanBase() = default;
  /// The writable view of the slot (data_view's shape), kept valid by `base`.
  virtual py::array data(py::handle base) = 0;
  /// The message being filled (its metadata: frame_id, timestamp_ns), as a view.
  virtual py::object message(py::handle base) = 0;
};

template <class T>
struct LoanOf final : LoanBase {
  explicit LoanOf(Loan<T> l) : loan(std::move(l)) {}
  py::array data(py::handle base) override {
    T& m = *loan;
    return array_over(array_shape(m), m.data_mut().data(), m.data().size(), base, true);
  }
  py::object message(py::handle base) override {
    return py::cast(&*loan, py::return_value_policy::reference_internal, base);
  }
  Loan<T> loan;
};

class PyLoan {
 public:
  /// `handle`: the topic handle that lent it, kept open (its pool mapped) while the loan lives.
  PyLoan(std::unique_ptr<LoanBase> l, std::shared_ptr<const void> handle)
      : loan_(std::move(l)), handle_(std::move(handle)) {}
  LoanBase* get() const noexcept { return loan_.get(); }
  /// Gives the loan to a send: the arrays handed out turn read-only. The LoanBase stays alive
  /// while views of the (moved-from, empty) message exist.
  std::shared_ptr<LoanBase> take() {
    for (auto& weak : arrays_) {
      py::object a = weak();
      if (!a.is_none()) a.attr("setflags")(py::arg("write") = false);
    }
    arrays_.clear();
    sent_ = std::move(loan_);
    return sent_;
  }
  bool sent() const noexcept { return !loan_; }
  py::array data(py::handle self) {
    check();
    py::array a = loan_->data(self);
    std::erase_if(arrays_, [](const py::weakref& w) { return w().is_none(); });
    arrays_.emplace_back(a);
    return a;
  }
  py::object message(py::handle self) {
    check();
    return loan_->message(self);
  }

 private:
  void check() const {
    if (!loan_) throw py::value_error("this loan was sent: its slot belongs to the subscribers now");
  }
  std::shared_ptr<LoanBase> loan_;
  std::shared_ptr<LoanBase> sent_;  // keeps the moved-from message alive for views taken before
  std::shared_ptr<const void> handle_;  // keeps the pool mapped while arrays (this loan is their base) live
  std::vector<py::weakref> arrays_;
};

}  // namespace horus::python
