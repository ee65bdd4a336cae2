// What libhorus.so exports (docs/ABI.md). The library's parts are compiled with
// -fvisibility=hidden; a public header puts its declarations between HORUS_API_BEGIN and
// HORUS_API_END (default visibility: a program may link against them), and a declaration of a
// folder's src/ that a program outside the library must reach (the fuzzer) is marked HORUS_API.
#pragma once

#if defined(__GNUC__)
#define HORUS_API __attribute__((visibility("default")))
#define HORUS_API_BEGIN _Pragma("GCC visibility push(default)")
#define HORUS_API_END _Pragma("GCC visibility pop")
#else
#define HORUS_API
#define HORUS_API_BEGIN
#define HORUS_API_END
#endif
