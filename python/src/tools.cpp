// horus.Fleet, horus.config (check / explain) and horus.record (Recorder / Player).
#include <fmt/format.h>
#include <pybind11/chrono.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <memory>
#include <set>
#include <type_traits>
#include <string>

#include "gil.hpp"
#include "horus/config.hpp"
#include "horus/fleet.hpp"
#include "horus/record/player.hpp"
#include "horus/record/recorder.hpp"
#include "horus/record/standard.hpp"
#include "horus/transport_registry.hpp"
#include "topic_options.hpp"
#include "typed.hpp"

namespace horus::python {

namespace {

template <class T>
T ok_or_raise(Result<T> r) {
  if (!r) raise(r.error());
  return std::move(*r);
}
void ok_or_raise(Result<void> r) {
  if (!r) raise(r.error());
}

// f() with the GIL released (its result is turned into Python, or raised, after the GIL is back).
template <class F>
auto without_gil(F&& f) {
  py::gil_scoped_release free;
  return f();
}

// A Fleet is destroyed without the GIL: its thread may be waiting for it to run a callback.
struct FleetDeleter {
  void operator()(Fleet* f) const {
    py::gil_scoped_release free;
    delete f;
  }
};
using FleetPtr = std::unique_ptr<Fleet, FleetDeleter>;

FleetPtr open_fleet(std::optional<std::string> transport, std::optional<std::uint32_t> misses) {
  FleetOptions o;
  o.transport = std::move(transport);
  o.misses = misses;
  auto f = Fleet::open(o);
  if (!f) raise(f.error());
  return FleetPtr(f->release());
}

// A chosen setting's value in Python: numbers as numbers, durations in seconds, named values as
// the file writes them; an unset one is its default value, or None when it has none.
template <class K, class D>
py::object chosen(K of, const std::optional<typename K::type>& v, const D& default_value) {
  using T = typename K::type;
  std::optional<T> x = v;
  if constexpr (!std::is_same_v<D, std::nullopt_t>)
    if (!x) x = T(default_value);
  if (!x) return py::none();
  if constexpr (std::is_same_v<T, std::chrono::nanoseconds>) return py::float_(static_cast<double>(x->count()) / 1e9);
  else if constexpr (std::is_same_v<T, bool>) return py::bool_(*x);
  else if constexpr (std::is_floating_point_v<T>) return py::float_(*x);
  else if constexpr (std::is_integral_v<T>) return py::int_(*x);
  else return py::str(setting::format(of, *x));
}

py::dict config_explain(const std::string& topic, const std::optional<std::string>& file) {
  if (auto ok = validate_topic_name(topic); !ok) raise(ok.error());
  std::optional<Config> own;
  const Config* config = nullptr;
  if (file) {
    own = ok_or_raise(Config::load(*file));
    config = &*own;
  } else {
    config = ok_or_raise(config_from_environment());
  }
  const TopicChoice c = ok_or_raise(choose(topic, TopicOptions{}, config));
  auto from = [&](Source s) {
    if (s == Source::File && c.rule != nullptr)
      return fmt::format("file {}, line {}: rule '{}'", config->file(), c.rule->line, c.rule->match);
    return std::string(to_string(s));
  };
  auto entry = [](py::object value, std::string source) {
    py::dict d;
    d["value"] = std::move(value);
    d["from"] = std::move(source);
    return d;
  };
  py::dict out;
  out["topic"] = topic;
  out["file"] = config != nullptr ? py::object(py::str(config->file())) : py::object(py::none());
  out["rule"] = c.rule != nullptr ? py::object(py::str(c.rule->match)) : py::object(py::none());
  out["scope"] = entry(py::str(std::string(to_string(c.backend.scope()))), from(c.backend_from));
  out["backend"] = entry(py::str(std::string(to_string(c.backend))), from(c.backend_from));
  if (auto wire = wire_name(c.backend, topic)) out["wire_name"] = *wire;
  out["verbose"] = entry(py::bool_(c.verbose), verbose_origin(c));
#define HORUS_EXPLAIN_SETTING(member, Kind, Rule, key, example, dflt, unset, doc) \
  HORUS_SETTING_IF_PLAIN_##Rule(out[#member] = entry(chosen(setting::Kind{}, c.member, dflt), from(c.member##_from));)
  HORUS_TOPIC_SETTINGS(HORUS_EXPLAIN_SETTING)
#undef HORUS_EXPLAIN_SETTING
  if (is_network(c.backend)) {
    const auto net = ok_or_raise(net::config_from_environment(config));
    py::dict s;
    s["mode"] = std::string(net::to_string(net.security.mode));
    s["identity"] = net.security.identity;
    s["keystore"] = net.security.keystore;
    out["security"] = s;
  }
  return out;
}

// The same checks as `horus config check`: the file, then what each transport checks itself.
std::size_t config_check(const std::string& file) {
  const Config c = ok_or_raise(Config::load(file));
  const auto net = ok_or_raise(net::config_of(c));
  std::set<std::string> used;
  if (c.network().backend) used.insert(*c.network().backend);
  for (const auto& r : c.rules())
    if (r.backend) used.insert(*r.backend);
  for (const std::string& name : net::transport_names()) {
    const auto* t = net::find_transport(name);
    if (t == nullptr || t->check == nullptr) continue;
    net::Config checked = net;
    if (!used.contains(name)) checked.peers.clear();
    ok_or_raise(t->check(checked));
  }
  return c.rules().size();
}

// horus.Fleet and the types it returns.
void bind_fleet(py::module_& m) {
  py::class_<FleetProcess>(m, "FleetProcess")
      .def_readonly("pid", &FleetProcess::pid)
      .def_readonly("name", &FleetProcess::name)
      .def_readonly("start_unix_ns", &FleetProcess::start_unix_ns);
  py::class_<FleetTopic>(m, "FleetTopic")
      .def_readonly("name", &FleetTopic::name)
      .def_readonly("type_name", &FleetTopic::type_name)
      .def_readonly("scope", &FleetTopic::scope)
      .def_readonly("transport", &FleetTopic::transport)
      .def_readonly("publishers", &FleetTopic::publishers)
      .def_readonly("subscribers", &FleetTopic::subscribers)
      .def_readonly("rate_hz", &FleetTopic::rate_hz)
      .def_readonly("messages", &FleetTopic::messages)
      .def_readonly("dropped", &FleetTopic::dropped);
  py::class_<FleetHost>(m, "FleetHost")
      .def_readonly("id", &FleetHost::id)
      .def_readonly("name", &FleetHost::name)
      .def_property_readonly("state", [](const FleetHost& h) { return std::string(to_string(h.state)); })
      .def_readonly("self", &FleetHost::self)
      .def_readonly("heartbeat_age", &FleetHost::heartbeat_age)
      .def_readonly("rtt", &FleetHost::rtt)
      .def_readonly("loss", &FleetHost::loss)
      .def_readonly("rejoins", &FleetHost::rejoins)
      .def_readonly("heartbeats", &FleetHost::heartbeats)
      .def_readonly("announced", &FleetHost::announced)
      .def_readonly("processes", &FleetHost::processes)
      .def_readonly("topics", &FleetHost::topics)
      .def("__repr__", [](const FleetHost& h) { return fmt::format("FleetHost('{}', {})", h.name, to_string(h.state)); });
  py::class_<FleetEvent>(m, "FleetEvent")
      .def_property_readonly("kind", [](const FleetEvent& e) { return std::string(to_string(e.kind)); })
      .def_readonly("host", &FleetEvent::host);
  py::class_<Fleet, FleetPtr>(m, "Fleet", "The hosts of the fleet, their states and topics; events as callbacks")
      .def(py::init(&open_fleet), py::arg("transport") = py::none(), py::arg("misses") = py::none())
      .def("hosts", &Fleet::hosts, py::call_guard<py::gil_scoped_release>())
      .def("host", &Fleet::host, py::call_guard<py::gil_scoped_release>())
      .def("refresh", &Fleet::refresh, py::call_guard<py::gil_scoped_release>())
      .def_property_readonly("transport", &Fleet::transport)
      .def_property_readonly("malformed", &Fleet::malformed)
      .def("on_change", [](Fleet& f, py::object cb) {
        auto held = std::make_shared<GilObject>(std::move(cb));
        return f.on_change([held](const FleetEvent& e) {
          py::gil_scoped_acquire gil;
          try {
            held->get()(e);
          } catch (py::error_already_set& err) {
            err.discard_as_unraisable("horus.Fleet.on_change callback");
          } catch (const std::exception& err) {  // a conversion's: nothing may escape into the fleet's thread
            PyErr_SetString(PyExc_RuntimeError, err.what());
            PyErr_WriteUnraisable(nullptr);
          }
        });
      }, py::arg("callback"), "Calls callback(event) on the fleet's thread when a host joins, is lost, rejoins or changes")
      .def("remove", &Fleet::remove);
}

void bind_config(py::module_& m) {
  py::module_ config = m.def_submodule("config", "The configuration file: check and explain (as horus config)");
  config.def("check", &config_check, py::arg("file"),
             "Validates a configuration file as `horus config check` does; the number of rules, or raises ConfigError");
  config.def("explain", &config_explain, py::arg("topic"), py::arg("file") = py::none(),
             "What topic gets from the environment and the file (HORUS_CONFIG unless file): a dict of value and source");
}

void bind_recorder(py::module_& record) {
  py::class_<Recorder>(record, "Recorder",
                       "Records topics into an MCAP file (or an LCM log: format='lcm'; a ROS 2 bag: profile='ros2')")
      .def(py::init([](const std::string& path, const std::string& format, std::uint64_t split_size,
                       const std::string& profile) {
             RecorderOptions o;
             o.format = ok_or_raise(parse_record_format(format));
             o.profile = ok_or_raise(parse_record_profile(profile));
             o.split_size = split_size;
             return ok_or_raise(Recorder::open(path, o));
           }),
           py::arg("path"), py::arg("format") = "mcap", py::arg("split_size") = 0, py::arg("profile") = "horus")
      .def("add", [](Recorder& r, const std::string& name, py::handle type, const py::kwargs& kw) {
        ok_or_raise(r.add(ok_or_raise(open_standard_source(type_of(type).qualified, name, topic_options(kw)))));
      }, py::arg("name"), py::arg("type"))
      .def("recording", &Recorder::recording)
      .def("stats", [](const Recorder& r) {
        const RecorderStats s = r.stats();
        py::dict d;
        d["messages"] = s.messages;
        d["bytes"] = s.bytes;
        d["file_bytes"] = s.file_bytes;
        d["files"] = s.files;
        py::dict topics;
        for (const auto& t : s.topics) topics[py::str(t.topic)] = py::dict(py::arg("type") = t.type,
                                                                           py::arg("messages") = t.messages,
                                                                           py::arg("dropped") = t.dropped);
        d["topics"] = topics;
        return d;
      })
      .def("flush", [](Recorder& r) { ok_or_raise(without_gil([&] { return r.flush(); })); })
      .def("close", [](Recorder& r) { ok_or_raise(without_gil([&] { return r.close(); })); })
      .def("__enter__", [](py::object self) { return self; })
      .def("__exit__", [](Recorder& r, py::args) { ok_or_raise(without_gil([&] { return r.close(); })); });
}

void bind_player(py::module_& record) {
  py::class_<Player>(record, "Player", "Plays an MCAP file or an LCM log into topics")
      .def(py::init([](const std::string& path, bool recover) { return ok_or_raise(Player::open(path, recover)); }),
           py::arg("path"), py::arg("recover") = false)
      .def_property_readonly("topics", [](const Player& p) {
        py::dict d;
        for (const auto& c : p.channels()) {
          const MessageType* t = c.type.empty() ? find_type_by_lcm_fingerprint(c.lcm_fingerprint) : find_type(c.type);
          d[py::str(c.topic)] = t != nullptr ? t->cls : py::object(py::none());
        }
        return d;
      })
      .def_property_readonly("start_ns", &Player::start_ns)
      .def_property_readonly("end_ns", &Player::end_ns)
      .def("bind", [](Player& p, const std::string& topic, py::handle type, const std::string& to, const py::kwargs& kw) {
        const PlayChannel* c = p.channel(topic);
        if (c == nullptr) throw py::key_error(fmt::format("the recording has no topic '{}'", topic));
        const MessageType* found = !type.is_none() ? &type_of(type)
                                   : !c->type.empty()  ? &type_of(py::str(c->type))
                                                       : find_type_by_lcm_fingerprint(c->lcm_fingerprint);
        if (found == nullptr)
          throw py::type_error(fmt::format("'{}' was recorded without a type horus knows (LCM fingerprint {:016x}): pass "
                                           "type=horus.msg.X", topic, c->lcm_fingerprint));
        const MessageType& t = *found;
        std::uint64_t hash = 0;
        const std::string into = to.empty() ? c->horus_topic : to;
        auto sink = ok_or_raise(c->conversion != nullptr
                                    ? open_ros2_sink(t.qualified, into, *c->conversion, hash, topic_options(kw))
                                    : open_standard_sink(t.qualified, into, c->encoding == "lcm", hash, topic_options(kw)));
        if (c->encoding != "lcm" && c->type_hash != 0 && c->type_hash != hash)
          raise(Error(Errc::TypeMismatch, fmt::format("topic '{}' was recorded as {} with type hash {:016x}; {} has {:016x}",
                                                      topic, c->type, c->type_hash, t.qualified, hash)));
        ok_or_raise(p.bind(topic, std::move(sink)));
      }, py::arg("topic"), py::arg("type") = py::none(), py::arg("to") = "",
         "Plays recorded topic into a topic (named `to`, default the same; a ROS 2 bag's /a/b: a.b); the type from "
         "the recording unless given")
      .def("play", [](Player& p, double rate) {
        PlayOptions o;
        o.rate = rate;
        Result<PlayStats> s;
        {
          py::gil_scoped_release free;
          s = p.play(o);
        }
        const PlayStats st = ok_or_raise(std::move(s));
        py::dict d;
        d["published"] = st.published;
        d["failed"] = st.failed;
        d["first_error"] = st.first_error;
        d["per_topic"] = st.per_topic;
        return d;
      }, py::arg("rate") = 1.0, "Publishes the bound topics' messages, spaced as recorded (divided by rate; 0: at once)");
}

}  // namespace

void bind_tools(py::module_& m) {
  bind_fleet(m);
  bind_config(m);
  py::module_ record = m.def_submodule("record", "MCAP and LCM-log recording and replay");
  bind_recorder(record);
  bind_player(record);
}

}  // namespace horus::python
