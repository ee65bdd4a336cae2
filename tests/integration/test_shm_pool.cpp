// Large data between real processes: images, point clouds, depth images and tensors through the
// shared-memory pool; subscribers killed while holding images (their slots come back);
// publishers killed while filling a slot (no torn image is ever delivered).
// HORUS_KILL_LOOPS sets the number of kills per test (default 20).
#include <gtest/gtest.h>

#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <deque>
#include <string>
#include <thread>
#include <vector>

#include "horus/messages.hpp"
#include "horus/shm/shm_segment.hpp"
#include "horus/topic.hpp"
#include "process_support.hpp"
#include "test_support.hpp"

namespace {

using horus::Topic;
using horus::msg::Image;
using horus::msg::ImageEncoding;
using horus_test::Pipe;
using horus_test::spawn;
using horus_test::wait_for;

int kill_loops() {
  const char* v = std::getenv("HORUS_KILL_LOOPS");
  return v != nullptr ? std::max(1, std::atoi(v)) : 20;
}

// An image whose every byte is `value`, and whose timestamp says which value: a torn image
// (bytes of two messages) fails intact().
Image uniform(std::uint32_t h, std::uint32_t w, std::uint8_t value, std::uint64_t seq) {
  Image img(h, w, ImageEncoding::Mono8);
  img.fill({value});
  img.set_timestamp_ns(seq * 256 + value);
  return img;
}
bool intact(const Image& img) {
  const auto value = static_cast<std::uint8_t>(img.timestamp_ns() % 256);
  for (std::uint8_t b : img.data())
    if (b != value) return false;
  return !img.data().empty();
}

using ShmPool = horus_test::ShmProcessTest;  // HORUS_BACKEND unset; no /dev/shm leak after a test

TEST_F(ShmPool, EveryLargeDataTypeCrossesProcessesAndALoanArrivesIntact) {
  using namespace horus::msg;
  const auto base = horus_test::unique_name("pool.xproc");
  Topic<Image> img_sub(base + ".img");
  Topic<PointCloud> pc_sub(base + ".pc");
  Topic<DepthImage> depth_sub(base + ".depth");
  Topic<Tensor> tensor_sub(base + ".tensor");
  const pid_t child = spawn([&] {
    Topic<Image> img_pub(base + ".img");
    auto loan = img_pub.loan(*Image::describe(1080, 1920, ImageEncoding::Rgb8));
    if (!loan) return 3;
    auto bytes = (*loan)->data_mut();
    for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<std::uint8_t>(i % 251);
    (*loan)->set_frame_id("camera_front");
    img_pub.send(std::move(*loan));
    Topic<PointCloud> pc_pub(base + ".pc");
    pc_pub.send(PointCloud::from_xyz(std::vector<std::array<float, 3>>{{1, 2, 3}, {4, 5, 6}}));
    Topic<DepthImage> depth_pub(base + ".depth");
    auto depth = DepthImage::millimeters(2, 3);
    depth.set_depth(2, 1, 2.5f);
    depth_pub.send(depth);
    Topic<Tensor> tensor_pub(base + ".tensor");
    Tensor t({4, 4}, TensorDtype::F64);
    t.data_mut()[9] = 42;
    tensor_pub.send(t);
    return 0;
  });
  ASSERT_EQ(wait_for(child), 0);
  // The child is gone; its messages stay readable while the segments live.
  auto img = img_sub.recv();
  ASSERT_TRUE(img);
  EXPECT_EQ(img->width(), 1920u);
  EXPECT_EQ(img->frame_id(), "camera_front");
  for (std::size_t i = 0; i < img->data().size(); i += 997) ASSERT_EQ(img->data()[i], i % 251) << i;
  auto pc = pc_sub.recv();
  ASSERT_TRUE(pc);
  EXPECT_EQ(*pc, PointCloud::from_xyz(std::vector<std::array<float, 3>>{{1, 2, 3}, {4, 5, 6}}));
  auto depth = depth_sub.recv();
  ASSERT_TRUE(depth);
  EXPECT_FLOAT_EQ(*depth->get_depth(2, 1), 2.5f);
  auto t = tensor_sub.recv();
  ASSERT_TRUE(t);
  EXPECT_EQ(t->data()[9], 42);
}

TEST_F(ShmPool, ASubscriberKilledWhileHoldingImagesGivesItsSlotsBack) {
  const auto name = horus_test::unique_name("pool.holder");
  auto pub = Topic<Image>::with_capacity(name, 2);  // 4 pool slots for this publisher
  ASSERT_TRUE(pub);
  const int kills = kill_loops();
  for (int k = 0; k < kills; ++k) {
    Pipe subscribed, holding;
    const pid_t child = spawn([&] {
      Topic<Image> sub(name);
      subscribed.signal();
      std::deque<Image> held;
      const horus_test::Deadline deadline(std::chrono::seconds(20));
      while (held.size() < 4 && !deadline.expired())
        if (auto m = sub.recv()) held.push_back(std::move(*m));
      holding.signal();
      std::this_thread::sleep_for(std::chrono::seconds(30));  // killed long before
      return 0;
    });
    ASSERT_TRUE(subscribed.wait());
    for (std::uint8_t i = 0; i < 4; ++i) {
      auto r = pub->send_blocking(uniform(64, 64, i, static_cast<std::uint64_t>(k)), std::chrono::seconds(5));
      ASSERT_TRUE(r) << "round " << k << ": " << r.error().message();
    }
    ASSERT_TRUE(holding.wait());
    if (k == 0) {
      // While it lives, every slot is pinned: the publisher is refused, nothing is overwritten.
      auto r = pub->send_blocking(uniform(64, 64, 9, 0), std::chrono::milliseconds(100));
      ASSERT_FALSE(r);
      EXPECT_EQ(r.error().code(), horus::Errc::LimitReached) << r.error().message();
    }
    ::kill(child, SIGKILL);
    ASSERT_EQ(wait_for(child), 128 + SIGKILL);
    // Its pins die with it: the publisher gets every slot back (after the reaper runs).
    for (std::uint8_t i = 0; i < 4; ++i) {
      auto r = pub->send_blocking(uniform(64, 64, i, 1000), std::chrono::seconds(5));
      ASSERT_TRUE(r) << "after kill " << k << ", send " << int{i} << ": " << r.error().message();
    }
  }
  const auto ns = horus::shm::shm_namespace();
  ASSERT_TRUE(ns);
  auto view = horus::shm::SegmentView::open(horus::shm::segment_name(*ns, name));
  ASSERT_TRUE(view);
  ASSERT_TRUE(view->pool());
  EXPECT_EQ(view->pool().pinned_slots(), 0u);
}

TEST_F(ShmPool, APublisherKilledWhileFillingImagesNeverDeliversATornOne) {
  const auto name = horus_test::unique_name("pool.killpub");
  auto sub = Topic<Image>::with_capacity(name, 8);
  ASSERT_TRUE(sub);
  const int kills = kill_loops();
  std::uint64_t received = 0;
  for (int k = 0; k < kills; ++k) {
    Pipe started;
    const pid_t child = spawn([&] {
      Topic<Image> pub(name);
      started.signal();
      const auto desc = *Image::describe(128, 256, ImageEncoding::Mono8);
      for (std::uint64_t i = 0;; ++i) {
        const auto value = static_cast<std::uint8_t>(i * 7 + static_cast<std::uint64_t>(k));
        if (i % 2 == 0) {
          pub.send(uniform(128, 256, value, i));  // copied into a slot
        } else if (auto loan = pub.loan(desc)) {   // filled in place
          (*loan)->fill({value});
          (*loan)->set_timestamp_ns(i * 256 + value);
          pub.send(std::move(*loan));
        }
      }
      return 0;
    });
    ASSERT_TRUE(started.wait());
    const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(300 + (k * 397) % 3000);
    std::deque<Image> held;  // keep a few, as a slow consumer would
    while (std::chrono::steady_clock::now() < until) {
      if (auto m = sub->recv()) {
        ASSERT_TRUE(intact(*m)) << "torn image in round " << k;
        ++received;
        held.push_back(std::move(*m));
        if (held.size() > 3) held.pop_front();
      }
    }
    ::kill(child, SIGKILL);
    ASSERT_EQ(wait_for(child), 128 + SIGKILL);
    while (auto m = sub->recv()) {
      ASSERT_TRUE(intact(*m)) << "torn image after the kill in round " << k;
      ++received;
    }
    for (const auto& h : held) ASSERT_TRUE(intact(h)) << "a held image changed in round " << k;
  }
  EXPECT_GT(received, 0u);
  // The next publisher continues the topic.
  Topic<Image> pub(name);
  pub.send(uniform(8, 8, 77, 5));
  std::optional<Image> last;
  while (auto m = sub->recv()) last = std::move(m);
  ASSERT_TRUE(last);
  EXPECT_EQ(last->timestamp_ns(), 5u * 256 + 77);
}

TEST_F(ShmPool, OpeningWithAnotherPoolSlotSizeOrAsAnotherTypeIsAClearError) {
  const auto name = horus_test::unique_name("pool.mismatch");
  auto pub = Topic<Image>::with_capacity(name, 4, std::size_t{1} << 20);
  ASSERT_TRUE(pub);
  const pid_t child = spawn([&] {
    auto other = Topic<Image>::with_capacity(name, 4, std::size_t{2} << 20);
    if (other || other.error().code() != horus::Errc::ConfigMismatch) return 3;
    if (other.error().message().find("1048576") == std::string::npos) return 4;
    auto wrong = Topic<horus::msg::ImageDescriptor>::open(name);
    if (wrong || wrong.error().code() != horus::Errc::TypeMismatch) return 5;
    if (wrong.error().message().find("large data in a pool") == std::string::npos) return 6;
    auto same = Topic<Image>::open(name);  // no slot size given: accepts the existing one
    if (!same || same->max_message_size() != (std::size_t{1} << 20)) return 7;
    return 0;
  });
  EXPECT_EQ(wait_for(child), 0);
}

}  // namespace
