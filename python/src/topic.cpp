// horus.Topic, horus.Loan, horus.WaitSet and horus.Trigger (horus.Executor is Python: _executor.py).
#include <fmt/format.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "fields.hpp"
#include "loan.hpp"
#include "topic_options.hpp"
#include "typed.hpp"

namespace horus::python {

namespace {

using std::chrono::nanoseconds;

constexpr nanoseconds kSlice = std::chrono::milliseconds(100);  // waits check Python's signals this often

// A wait of up to `timeout` in slices, so that Ctrl-C (a Python signal handler) interrupts it:
// once(slice) until done(what it returned) or the time is up.
template <class F, class Done>
auto sliced(nanoseconds timeout, F&& once, Done&& done) -> decltype(once(timeout)) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    const auto left = std::chrono::duration_cast<nanoseconds>(deadline - std::chrono::steady_clock::now());
    auto r = once(std::max(nanoseconds::zero(), std::min(left, kSlice)));
    if (done(r) || left <= kSlice) return r;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  }
}
constexpr auto kTrue = [](bool b) { return b; };

// A topic handle shared by Python threads. One thread uses it at a time (Topic<T>'s rule): a
// call takes the handle's lock, waiting for it with the GIL released, so a thread that waits in
// recv_for (the GIL released) is never closed under, nor used by another thread meanwhile.
class PyTopic {
 public:
  PyTopic(const std::string& name, py::handle type, const py::kwargs& kw)
      : type_(&type_of(type)), topic_(type_->open(name, topic_options(kw))) {}
  const MessageType& type() const { return *type_; }

  /// f(AnyTopic&) with the handle locked; ValueError once the handle is closed.
  template <class F>
  decltype(auto) use(F&& f) {
    return use_shared([&](const std::shared_ptr<AnyTopic>& t) -> decltype(auto) { return f(*t); });
  }
  /// The same with the handle's owner (what a loan keeps).
  template <class F>
  decltype(auto) use_shared(F&& f) {
    std::unique_lock lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock()) {
      py::gil_scoped_release free;
      lock.lock();
    }
    if (!topic_) throw py::value_error("this topic was closed");
    return f(topic_);
  }
  bool closed() {
    return use_or([](AnyTopic&) { return false; }, true);
  }
  void close() {
    std::shared_ptr<AnyTopic> gone;  // destroyed unlocked (its last loan may hold it longer)
    {
      std::unique_lock lock(mutex_, std::try_to_lock);
      if (!lock.owns_lock()) {
        py::gil_scoped_release free;
        lock.lock();
      }
      gone = std::move(topic_);
    }
  }
  py::object recv_for(py::handle timeout) {
    const nanoseconds d = seconds(timeout, "recv_for(timeout)");
    py::object out = py::none();
    sliced(d, [&](nanoseconds part) {
      out = use([&](AnyTopic& t) { return t.recv_for(part); });
      return !out.is_none();
    }, kTrue);
    return out;
  }
  bool wait_for(py::handle timeout) {
    return sliced(seconds(timeout, "wait_for(timeout)"),
                  [&](nanoseconds part) { return use([&](AnyTopic& t) { return t.wait_for(part); }); }, kTrue);
  }
  void send_blocking(py::handle msg, py::handle timeout) {
    const nanoseconds d = seconds(timeout, "send_blocking(timeout)");
    auto timed_out = sliced(d, [&](nanoseconds part) { return use([&](AnyTopic& t) { return t.send_blocking(msg, part); }); },
                            [](const std::optional<Error>& e) { return !e; });
    if (timed_out) raise(*timed_out);
  }

 private:
  template <class F, class R>
  R use_or(F&& f, R if_closed) {
    std::unique_lock lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock()) {
      py::gil_scoped_release free;
      lock.lock();
    }
    return topic_ ? f(*topic_) : if_closed;
  }
  const MessageType* type_;
  std::mutex mutex_;
  std::shared_ptr<AnyTopic> topic_;
};

class PyWaitSet {
 public:
  WaitSet::Id attach(py::object what) {
    WaitSet::Id id = 0;
    if (py::isinstance<PyTopic>(what)) id = what.cast<PyTopic&>().use([&](AnyTopic& t) { return t.attach(ws_); });
    else if (py::isinstance<Trigger>(what)) id = ws_.attach(what.cast<const Trigger&>());
    else type_error("WaitSet.attach", "a horus.Topic or a horus.Trigger", what);
    attached_[id] = std::move(what);
    return id;
  }
  bool detach(py::handle what) {
    for (auto it = attached_.begin(); it != attached_.end(); ++it)
      if (it->second.is(what) || (py::isinstance<py::int_>(what) && it->first == what.cast<WaitSet::Id>())) {
        const bool ok = ws_.detach(it->first);
        attached_.erase(it);
        return ok;
      }
    return false;
  }
  py::list wait(py::handle timeout) {
    const nanoseconds d = seconds(timeout, "WaitSet.wait(timeout)");
    WaitSet::Result r = sliced(d, [&](nanoseconds part) {
      py::gil_scoped_release free;
      return ws_.wait(part);
    }, [](const WaitSet::Result& w) { return !w.timed_out(); });
    py::list out;
    for (WaitSet::Id id : r.ready)
      if (auto it = attached_.find(id); it != attached_.end()) out.append(it->second);
    return out;
  }
  std::size_t size() const { return ws_.size(); }

 private:
  WaitSet ws_;
  std::map<WaitSet::Id, py::object> attached_;
};

// Topic's constructor, sending and receiving, and loans.
void def_topic_traffic(py::class_<PyTopic>& c) {
  c.def(py::init<const std::string&, py::handle, const py::kwargs&>(), py::arg("name"), py::arg("type"))
      .def("send", [](PyTopic& s, py::handle msg) { s.use([&](AnyTopic& t) { t.send(msg); }); }, py::arg("msg"),
           "Publishes; never blocks (a full ring overwrites its oldest message)")
      .def("try_send", [](PyTopic& s, py::handle msg) { return s.use([&](AnyTopic& t) { return t.try_send(msg); }); },
           py::arg("msg"),
           "Publishes only if no subscriber would lose an unread message; False otherwise")
      .def("send_blocking", &PyTopic::send_blocking, py::arg("msg"), py::arg("timeout") = 1.0,
           "Publishes, waiting up to timeout seconds (None: for ever) for space; raises horus.TimeoutError")
      .def("recv", [](PyTopic& s) { return s.use([](AnyTopic& t) { return t.recv(); }); }, "The next message, or None")
      .def("try_recv", [](PyTopic& s) { return s.use([](AnyTopic& t) { return t.recv(); }); })
      .def("recv_for", &PyTopic::recv_for, py::arg("timeout"),
           "The next message, waiting up to timeout seconds (None: forever) with the GIL released; None when none came")
      .def("read_latest", [](PyTopic& s) { return s.use([](AnyTopic& t) { return t.read_latest(); }); }, "The newest message without consuming it")
      .def("wait_for", &PyTopic::wait_for, py::arg("timeout"))
      .def("loan",
           [](PyTopic& s, const py::args& args) {
             return s.use_shared([&](const std::shared_ptr<AnyTopic>& t) { return t->loan(args, t); });
           },
           py::keep_alive<0, 1>(),
           "Large data: a pool slot for Type.describe(*args) (or a descriptor), filled through Loan.data");
}

// Topic's counts and properties, its metrics, and its Python protocols (with, iteration, repr).
void def_topic_state(py::class_<PyTopic>& c) {
  c.def("publish_only", [](PyTopic& s) { s.use([](AnyTopic& t) { t.publish_only(); }); })
      .def("has_message", [](PyTopic& s) { return s.use([](AnyTopic& t) { return t.has_message(); }); })
      .def("pending_count", [](PyTopic& s) { return s.use([](AnyTopic& t) { return t.pending_count(); }); })
      .def("dropped_count", [](PyTopic& s) { return s.use([](AnyTopic& t) { return t.dropped_count(); }); })
      .def("deadline_missed_count", [](PyTopic& s) { return s.use([](AnyTopic& t) { return t.deadline_missed_count(); }); })
      .def("expired_count", [](PyTopic& s) { return s.use([](AnyTopic& t) { return t.expired_count(); }); })
      .def("network_errors", [](PyTopic& s) { return s.use([](AnyTopic& t) { return t.network_errors(); }); })
      .def_property_readonly("pub_count", [](PyTopic& s) { return s.use([](AnyTopic& t) { return t.pub_count(); }); })
      .def_property_readonly("sub_count", [](PyTopic& s) { return s.use([](AnyTopic& t) { return t.sub_count(); }); })
      .def_property_readonly("is_bridge", [](PyTopic& s) { return s.use([](AnyTopic& t) { return t.is_bridge(); }); })
      .def_property_readonly("capacity", [](PyTopic& s) { return s.use([](AnyTopic& t) { return t.capacity(); }); })
      .def_property_readonly("max_message_size", [](PyTopic& s) { return s.use([](AnyTopic& t) { return t.max_message_size(); }); })
      .def_property_readonly("name", [](PyTopic& s) { return s.use([](AnyTopic& t) { return std::string(t.name()); }); })
      .def_property_readonly("type", [](const PyTopic& s) { return s.type().cls; })
      .def_property_readonly("backend",
                             [](PyTopic& s) { return s.use([](AnyTopic& t) { return std::string(to_string(t.backend())); }); })
      .def_property_readonly("scope", [](PyTopic& s) {
        return s.use([](AnyTopic& t) { return std::string(to_string(t.backend().scope())); });
      })
      .def_property_readonly("closed", &PyTopic::closed)
      .def("metrics", [](PyTopic& s) {
        const TopicMetrics x = s.use([](AnyTopic& t) { return t.metrics(); });
        py::dict d;
        d["sent"] = x.messages_sent();
        d["received"] = x.messages_received();
        d["send_failures"] = x.send_failures();
        d["recv_failures"] = x.recv_failures();
        d["dropped"] = x.messages_dropped();
        d["topic_sent"] = x.topic_messages_sent();
        d["decode_failures"] = x.decode_failures();
        return d;
      })
      .def("close", &PyTopic::close, "Closes the handle now (else when it is garbage collected)")
      .def("__enter__", [](py::object self) { return self; })
      .def("__exit__", [](PyTopic& s, py::args) { s.close(); })
      .def("__iter__", [](py::object self) { return self; })
      .def("__next__", [](PyTopic& s) { return s.recv_for(py::none()); }, "Blocks until the next message")
      .def("__repr__", [](PyTopic& s) {
        if (s.closed()) return fmt::format("horus.Topic(horus.msg.{}, closed)", s.type().short_name);
        return s.use([&](AnyTopic& t) {
          return fmt::format("horus.Topic('{}', horus.msg.{}, scope={}, backend={})", t.name(), s.type().short_name,
                             to_string(t.backend().scope()), to_string(t.backend()));
        });
      });
}

// Trigger and WaitSet.
void bind_waiting(py::module_& m) {
  py::class_<Trigger>(m, "Trigger", "A condition a WaitSet waits on, fired from any thread")
      .def(py::init<>())
      .def("fire", &Trigger::fire)
      .def("reset", &Trigger::reset)
      .def_property_readonly("fired", &Trigger::fired);

  py::class_<PyWaitSet>(m, "WaitSet", "Waits on several topics and triggers at once")
      .def(py::init<>())
      .def("attach", &PyWaitSet::attach, py::arg("topic_or_trigger"))
      .def("detach", &PyWaitSet::detach)
      .def("wait", &PyWaitSet::wait, py::arg("timeout") = py::none(),
           "The attached topics and triggers that are ready (empty when the timeout passed)")
      .def("__len__", &PyWaitSet::size);
}

}  // namespace

void bind_topics(py::module_& m) {
  py::class_<PyLoan>(m, "Loan", "A pool slot lent by Topic.loan(): fill .data, then topic.send(loan)")
      .def_property_readonly("data", [](py::object self) { return self.cast<PyLoan&>().data(self); })
      .def_property_readonly("message", [](py::object self) { return self.cast<PyLoan&>().message(self); })
      .def_property_readonly("sent", &PyLoan::sent);

  py::class_<PyTopic> topic(m, "Topic",
                            "A typed topic: horus.Topic('odom', horus.msg.Odometry, capacity=..., scope=...)");
  def_topic_traffic(topic);
  def_topic_state(topic);

  bind_waiting(m);
}

}  // namespace horus::python
