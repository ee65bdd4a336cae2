// Google Benchmark suite of the local path: Topic operations and the boost spsc_queue baseline.
// The latency table with the floor and the targets is horus-latency-local (horus_latency.cpp).
#include <benchmark/benchmark.h>
#include <boost/lockfree/spsc_queue.hpp>

#include <memory>

#include "horus/horus.hpp"

using horus::msg::CmdVel;

static void BM_TopicSameThreadSendRecv_CmdVel(benchmark::State& state) {
  horus::Topic<CmdVel> pub("gbench.same_thread"), sub("gbench.same_thread");
  CmdVel msg = CmdVel::make(1.0f, 0.5f);
  for (auto _ : state) {
    ++msg.stamp_nanos;
    pub.send(msg);
    auto m = sub.recv();
    benchmark::DoNotOptimize(m);
  }
}
BENCHMARK(BM_TopicSameThreadSendRecv_CmdVel);

static void BM_BoostSpscSameThreadPushPop_CmdVel(benchmark::State& state) {
  auto q = std::make_unique<boost::lockfree::spsc_queue<CmdVel, boost::lockfree::capacity<1024>>>();
  CmdVel msg = CmdVel::make(1.0f, 0.5f);
  for (auto _ : state) {
    ++msg.stamp_nanos;
    q->push(msg);
    CmdVel out;
    benchmark::DoNotOptimize(q->pop(out));
    benchmark::DoNotOptimize(out);
  }
}
BENCHMARK(BM_BoostSpscSameThreadPushPop_CmdVel);

static void BM_TopicSendOnly_CmdVel(benchmark::State& state) {
  horus::Topic<CmdVel> pub("gbench.send_only");
  CmdVel msg = CmdVel::make(1.0f, 0.5f);
  for (auto _ : state) {
    ++msg.stamp_nanos;
    pub.send(msg);
  }
  benchmark::DoNotOptimize(pub.pub_count());
}
BENCHMARK(BM_TopicSendOnly_CmdVel);

static void BM_TopicTrySendRecv_CmdVel(benchmark::State& state) {
  horus::Topic<CmdVel> pub("gbench.try_send"), sub("gbench.try_send");
  CmdVel msg = CmdVel::make(1.0f, 0.5f);
  for (auto _ : state) {
    ++msg.stamp_nanos;
    benchmark::DoNotOptimize(pub.try_send(msg));
    auto m = sub.recv();
    benchmark::DoNotOptimize(m);
  }
}
BENCHMARK(BM_TopicTrySendRecv_CmdVel);

static void BM_TopicReadLatest_CmdVel(benchmark::State& state) {
  horus::Topic<CmdVel> pub("gbench.latest"), sub("gbench.latest");
  pub.send(CmdVel::make(1.0f, 0.5f));
  for (auto _ : state) {
    auto m = sub.read_latest();
    benchmark::DoNotOptimize(m);
  }
}
BENCHMARK(BM_TopicReadLatest_CmdVel);

static void BM_TopicSameThreadSendRecv_JointState(benchmark::State& state) {
  horus::Topic<horus::msg::JointState> pub("gbench.joint_state"), sub("gbench.joint_state");
  horus::msg::JointState msg{};
  for (auto _ : state) {
    ++msg.timestamp_ns;
    pub.send(msg);
    auto m = sub.recv();
    benchmark::DoNotOptimize(m);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * sizeof(msg)));
}
BENCHMARK(BM_TopicSameThreadSendRecv_JointState);

static void BM_TopicRecvFromFourPublishers_CmdVel(benchmark::State& state) {
  horus::Topic<CmdVel> sub("gbench.four_pubs");
  std::vector<horus::Topic<CmdVel>> pubs;
  for (int i = 0; i < 4; ++i) pubs.emplace_back("gbench.four_pubs");
  CmdVel msg = CmdVel::make(1.0f, 0.5f);
  std::size_t k = 0;
  for (auto _ : state) {
    pubs[k++ & 3].send(msg);
    auto m = sub.recv();
    benchmark::DoNotOptimize(m);
  }
}
BENCHMARK(BM_TopicRecvFromFourPublishers_CmdVel);

BENCHMARK_MAIN();
