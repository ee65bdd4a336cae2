// Google Benchmark suite of the message library on the in-process Topic: what a serialized
// (variable-size) or large message costs compared with a fixed-size one, and with a plain
// memcpy of the same bytes measured in the same run (the baseline: one copy is the least any
// copying transport does).
//
//   build/default/bench/horus_bench_messages --benchmark_min_time=0.2
//
// SetBytesProcessed makes the tool print bytes/s; for each payload the ratio to the memcpy
// row of the same size is the number to read.
#include <benchmark/benchmark.h>

#include <cstring>
#include <string>
#include <vector>

#include "horus/wire/local.hpp"
#include "horus/horus.hpp"
#include "horus/msg/all.hpp"
#include "horus/msg/generic_value.hpp"

namespace {

using namespace horus::msg;

std::string bench_name(const char* base) {
  static int n = 0;
  return std::string("gbench.msg.") + base + "." + std::to_string(n++);
}

OccupancyGrid make_grid(std::uint32_t side) {
  OccupancyGrid g = OccupancyGrid::make(side, side, 0.05f, Pose2D{});
  for (std::size_t i = 0; i < g.data.size(); ++i) g.data[i] = static_cast<std::int8_t>(i % 101);
  return g;
}

Image make_image(std::uint32_t h, std::uint32_t w) {
  Image img(h, w, ImageEncoding::Rgb8);
  auto px = img.data_mut();
  for (std::size_t i = 0; i < px.size(); ++i) px[i] = static_cast<std::uint8_t>(i);
  return img;
}

// Same-thread send + recv through an in-process topic.
template <class T>
void send_recv(benchmark::State& state, const T& msg, std::size_t bytes, const char* name) {
  const auto topic = bench_name(name);
  horus::Topic<T> pub(topic), sub(topic);
  for (auto _ : state) {
    pub.send(msg);
    auto m = sub.recv();
    benchmark::DoNotOptimize(m);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * bytes));
  state.counters["msg_bytes"] = static_cast<double>(bytes);
}

void memcpy_baseline(benchmark::State& state) {
  const auto bytes = static_cast<std::size_t>(state.range(0));
  std::vector<std::byte> src(bytes, std::byte{1}), dst(bytes);
  for (auto _ : state) {
    std::memcpy(dst.data(), src.data(), bytes);
    benchmark::DoNotOptimize(dst.data());
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * bytes));
}

}  // namespace

// Fixed-size messages, for scale.
static void BM_SendRecv_CmdVel(benchmark::State& state) {
  send_recv(state, CmdVel::make(1.0f, 0.5f), sizeof(CmdVel), "cmdvel");
}
BENCHMARK(BM_SendRecv_CmdVel);

static void BM_SendRecv_LaserScan(benchmark::State& state) {
  send_recv(state, LaserScan::make(), sizeof(LaserScan), "scan");
}
BENCHMARK(BM_SendRecv_LaserScan);

// Serialized messages.
static void BM_SendRecv_CompressedImage_32KiB(benchmark::State& state) {
  const auto img = CompressedImage::make("jpeg", std::vector<std::uint8_t>(32 * 1024, 7), 640, 480);
  send_recv(state, img, img.data.size(), "jpeg");
}
BENCHMARK(BM_SendRecv_CompressedImage_32KiB);

static void BM_SendRecv_OccupancyGrid(benchmark::State& state) {
  const auto side = static_cast<std::uint32_t>(state.range(0));
  const auto grid = make_grid(side);
  send_recv(state, grid, grid.data.size(), "grid");
}
BENCHMARK(BM_SendRecv_OccupancyGrid)->Arg(200)->Arg(1000);

// Large data, in-process today (serialized: encode, slot copy, decode).
static void BM_SendRecv_Image(benchmark::State& state) {
  const auto h = static_cast<std::uint32_t>(state.range(0)), w = static_cast<std::uint32_t>(state.range(1));
  const auto img = make_image(h, w);
  send_recv(state, img, img.data().size(), "image");
}
BENCHMARK(BM_SendRecv_Image)->Args({480, 640})->Args({1080, 1920})->Unit(benchmark::kMicrosecond);

// The codec alone.
static void BM_CodecEncode_OccupancyGrid_1000(benchmark::State& state) {
  const auto grid = make_grid(1000);
  std::vector<std::byte> out(horus::codec::encoded_size(grid));
  for (auto _ : state) {
    benchmark::DoNotOptimize(horus::codec::encode(grid, std::span<std::byte>(out)));
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * out.size()));
}
BENCHMARK(BM_CodecEncode_OccupancyGrid_1000);

static void BM_CodecDecode_OccupancyGrid_1000(benchmark::State& state) {
  const auto bytes = horus::codec::encode(make_grid(1000));
  for (auto _ : state) {
    auto g = horus::codec::decode<OccupancyGrid>(bytes);
    benchmark::DoNotOptimize(g);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * bytes.size()));
}
BENCHMARK(BM_CodecDecode_OccupancyGrid_1000);

// GenericMessage: MessagePack in and out of a small map.
static void BM_GenericMessage_FromValueToValue(benchmark::State& state) {
  const std::map<std::string, double> reading{{"temperature", 22.5}, {"humidity", 60.0}, {"pressure", 1013.2}};
  for (auto _ : state) {
    auto g = GenericMessage::from_value(reading);
    auto back = g->to_value<std::map<std::string, double>>();
    benchmark::DoNotOptimize(back);
  }
}
BENCHMARK(BM_GenericMessage_FromValueToValue);

// Baseline: one memcpy of the same payload sizes (32 KiB, 200x200 grid, 1000x1000 grid,
// 640x480 and 1920x1080 RGB).
BENCHMARK(memcpy_baseline)
    ->Arg(32 * 1024)
    ->Arg(200 * 200)
    ->Arg(1000 * 1000)
    ->Arg(480 * 640 * 3)
    ->Arg(1080 * 1920 * 3)
    ->Name("BM_Memcpy_Baseline");

BENCHMARK_MAIN();
