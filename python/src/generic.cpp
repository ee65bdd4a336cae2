// GenericMessage with Python values: GenericMessage.from_value(dict) packs a dict, list, str,
// bytes, number, bool or None with MessagePack (as HORUS's from_value); to_value() unpacks it.
#ifndef MSGPACK_NO_BOOST
#define MSGPACK_NO_BOOST
#endif
#include <fmt/format.h>
#include <pybind11/pybind11.h>

#include <msgpack.hpp>

#include <string>

#include "horus/msg/generic.hpp"
#include "fields.hpp"
#include "typed.hpp"

namespace horus::python {

namespace {

constexpr int kMaxDepth = 64;

void pack(msgpack::packer<msgpack::sbuffer>& p, py::handle h, const std::string& path, int depth) {
  if (depth > kMaxDepth) throw py::value_error(fmt::format("GenericMessage.from_value: {} nests over {} levels", path, kMaxDepth));
  if (h.is_none()) {
    p.pack_nil();
  } else if (py::isinstance<py::bool_>(h)) {
    h.cast<bool>() ? p.pack_true() : p.pack_false();
  } else if (py::isinstance<py::int_>(h)) {
    if (h.cast<py::int_>() < py::int_(0)) p.pack(h.cast<std::int64_t>());
    else p.pack(h.cast<std::uint64_t>());
  } else if (py::isinstance<py::float_>(h)) {
    p.pack(h.cast<double>());
  } else if (py::isinstance<py::str>(h)) {
    p.pack(h.cast<std::string>());
  } else if (py::isinstance<py::bytes>(h)) {
    const std::string b = h.cast<std::string>();
    p.pack_bin(static_cast<std::uint32_t>(b.size()));
    p.pack_bin_body(b.data(), static_cast<std::uint32_t>(b.size()));
  } else if (py::isinstance<py::dict>(h)) {
    const auto d = h.cast<py::dict>();
    p.pack_map(static_cast<std::uint32_t>(d.size()));
    for (const auto& [k, v] : d) {
      pack(p, k, path, depth + 1);
      pack(p, v, path + "[" + py::repr(k).cast<std::string>() + "]", depth + 1);
    }
  } else if (py::isinstance<py::list>(h) || py::isinstance<py::tuple>(h)) {
    p.pack_array(static_cast<std::uint32_t>(py::len(h)));
    std::size_t i = 0;
    for (const auto& e : h) pack(p, e, path + "[" + std::to_string(i++) + "]", depth + 1);
  } else {
    python::type_error(path, "a dict, list, tuple, str, bytes, int, float, bool or None", h);
  }
}

py::object unpack(const msgpack::object& o, int depth) {
  if (depth > kMaxDepth) throw py::value_error("GenericMessage.to_value: the payload nests too deep");
  switch (o.type) {
    case msgpack::type::NIL: return py::none();
    case msgpack::type::BOOLEAN: return py::bool_(o.via.boolean);
    case msgpack::type::POSITIVE_INTEGER: return py::int_(o.via.u64);
    case msgpack::type::NEGATIVE_INTEGER: return py::int_(o.via.i64);
    case msgpack::type::FLOAT32:
    case msgpack::type::FLOAT64: return py::float_(o.via.f64);
    case msgpack::type::STR: return py::str(o.via.str.ptr, o.via.str.size);
    case msgpack::type::BIN: return py::bytes(o.via.bin.ptr, o.via.bin.size);
    case msgpack::type::ARRAY: {
      py::list out;
      for (std::uint32_t i = 0; i < o.via.array.size; ++i) out.append(unpack(o.via.array.ptr[i], depth + 1));
      return out;
    }
    case msgpack::type::MAP: {
      py::dict out;
      for (std::uint32_t i = 0; i < o.via.map.size; ++i)
        out[unpack(o.via.map.ptr[i].key, depth + 1)] = unpack(o.via.map.ptr[i].val, depth + 1);
      return out;
    }
    case msgpack::type::EXT: break;
  }
  throw py::value_error("GenericMessage.to_value: the payload holds a MessagePack extension, which has no Python value");
}

}  // namespace

void bind_generic(py::module_& msg) {
  auto c = py::reinterpret_borrow<py::class_<msg::GenericMessage>>(msg.attr("GenericMessage"));
  c.def_static("from_value", [](py::handle value, const std::string& metadata) {
    msgpack::sbuffer buf;
    msgpack::packer<msgpack::sbuffer> p(buf);
    pack(p, value, "value", 0);
    const std::span<const std::uint8_t> bytes(reinterpret_cast<const std::uint8_t*>(buf.data()), buf.size());
    auto m = metadata.empty() ? msg::GenericMessage::make(bytes) : msg::GenericMessage::with_metadata(bytes, metadata);
    if (!m) throw py::value_error("GenericMessage.from_value: " + m.error());
    return *m;
  }, py::arg("value"), py::arg("metadata") = "", "Packs a dict (list, str, number...) with MessagePack, at most 4096 bytes");
  c.def("to_value", [](const msg::GenericMessage& m) {
    const auto bytes = m.data();
    try {
      const msgpack::object_handle h = msgpack::unpack(reinterpret_cast<const char*>(bytes.data()), bytes.size());
      return unpack(h.get(), 0);
    } catch (const msgpack::unpack_error& e) {
      throw py::value_error(fmt::format("GenericMessage.to_value: the payload is not MessagePack ({})", e.what()));
    }
  }, "The payload's value (from_value's dict, ...)");
  c.def_property_readonly("payload", [](const msg::GenericMessage& m) {
    const auto b = m.data();
    return py::bytes(reinterpret_cast<const char*>(b.data()), b.size());
  });
}

}  // namespace horus::python
