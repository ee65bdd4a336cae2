// horus-msg-catalogue: prints the catalogue of standard messages (a Markdown table made from
// the reflection) and keeps the copy in messages/README.md current.
//
//   horus-msg-catalogue                      print the table
//   horus-msg-catalogue --check README.md    exit 1 (and say how to fix it) if README's copy differs
//   horus-msg-catalogue --update README.md   rewrite README's copy
//
// The copy sits between the lines "<!-- catalogue:begin -->" and "<!-- catalogue:end -->".
#include <fmt/format.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>

#include "horus/msg/all.hpp"
#include "horus/reflect.hpp"

namespace {

constexpr std::string_view kBegin = "<!-- catalogue:begin -->";
constexpr std::string_view kEnd = "<!-- catalogue:end -->";

std::string short_name(std::string_view qualified) {
  const auto pos = qualified.rfind("::");
  return std::string(pos == std::string_view::npos ? qualified : qualified.substr(pos + 2));
}

std::string catalogue() {
  std::string rows;
  std::size_t count = 0, fixed = 0;
  horus::msg::for_each_message([&]<class T>(std::string_view domain) {
    ++count;
    const bool pod = horus::reflect::is_fixed_size<T>;
    if (pod) ++fixed;
    std::string fields;
    horus::reflect::for_each_field_desc<T>([&](const auto& fd) {
      using F = typename std::remove_cvref_t<decltype(fd)>::type;
      if (!fields.empty()) fields += ", ";
      fields += fmt::format("{}: {}", fd.name, horus::reflect::type_label<F>());
    });
    rows += fmt::format("| {} | {} | {} | {} | `{:016x}` | {} |\n", short_name(horus::type_name<T>()), domain,
                        pod ? fmt::format("{} B", sizeof(T)) : std::string("variable"), pod ? "POD" : "serialized",
                        horus::type_hash<T>, fields);
  });
  std::string out;
  out += fmt::format("{} message types: {} fixed-size (POD, copied into slots) and {} variable-size "
                     "(serialized into slots).\n\n",
                     count, fixed, count - fixed);
  out += "| Message | Domain | Size | Layout | Type hash | Fields |\n";
  out += "|---|---|---|---|---|---|\n";
  out += rows;
  return out;
}

bool read_file(const std::string& path, std::string& out) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::ostringstream ss;
  ss << in.rdbuf();
  out = ss.str();
  return true;
}

// Splits README text around the markers; false when they are missing or out of order.
bool split(const std::string& text, std::size_t& body_begin, std::size_t& body_end) {
  const auto b = text.find(kBegin);
  const auto e = text.find(kEnd);
  if (b == std::string::npos || e == std::string::npos || e < b) return false;
  body_begin = b + kBegin.size() + 1;  // after the marker's line
  body_end = e;
  return body_begin <= body_end;
}

int usage() {
  std::fputs("usage: horus-msg-catalogue [--check README.md | --update README.md]\n", stderr);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string table = catalogue();
  if (argc == 1) {
    std::fputs(table.c_str(), stdout);
    return 0;
  }
  if (argc != 3) return usage();
  const std::string mode = argv[1], path = argv[2];
  if (mode != "--check" && mode != "--update") return usage();
  std::string text;
  if (!read_file(path, text)) {
    std::fprintf(stderr, "horus-msg-catalogue: cannot read %s\n", path.c_str());
    return 2;
  }
  std::size_t b = 0, e = 0;
  if (!split(text, b, e)) {
    std::fprintf(stderr, "horus-msg-catalogue: %s has no '%s' ... '%s' section\n", path.c_str(), kBegin.data(),
                 kEnd.data());
    return 2;
  }
  const std::string current = text.substr(b, e - b);
  if (mode == "--check") {
    if (current == table) return 0;
    std::fprintf(stderr,
                 "horus-msg-catalogue: the catalogue in %s is stale (the messages changed).\n"
                 "Regenerate it: build/default/messages/horus-msg-catalogue --update %s\n",
                 path.c_str(), path.c_str());
    return 1;
  }
  text.replace(b, e - b, table);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  if (!out) {
    std::fprintf(stderr, "horus-msg-catalogue: cannot write %s\n", path.c_str());
    return 2;
  }
  std::printf("horus-msg-catalogue: %s updated\n", path.c_str());
  return 0;
}
