// Default quality of service of a message type on the network backends (DDS), by type:
//
//   reliability   durability       types
//   best effort   volatile         high-rate sensor data: Image, CompressedImage, DepthImage,
//                                  PointCloud, LaserScan, Imu, Tensor, AudioFrame, SegmentationMask
//   reliable      transient local  latched state a late joiner needs: OccupancyGrid, CostMap
//   reliable      volatile         everything else (commands, poses, transforms, heartbeats, ...)
//
// History is KEEP_LAST with the topic's capacity as depth. TopicOptions::reliability and
// ::durability override the defaults per topic; a user's own type gets its defaults by
// specializing horus::net::default_qos:
//
//   template <> struct horus::net::default_qos<my::Scan> : horus::net::sensor_data_qos {};
#pragma once

#include "horus/network.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::msg {
class Image;
struct CompressedImage;
class DepthImage;
class PointCloud;
struct LaserScan;
struct Imu;
class Tensor;
struct AudioFrame;
struct SegmentationMask;
struct OccupancyGrid;
struct CostMap;
}  // namespace horus::msg

namespace horus::net {

struct reliable_qos {
  static constexpr Reliability reliability = Reliability::Reliable;
  static constexpr Durability durability = Durability::Volatile;
};
struct sensor_data_qos {
  static constexpr Reliability reliability = Reliability::BestEffort;
  static constexpr Durability durability = Durability::Volatile;
};
struct latched_qos {
  static constexpr Reliability reliability = Reliability::Reliable;
  static constexpr Durability durability = Durability::TransientLocal;
};

template <class T>
struct default_qos : reliable_qos {};

template <> struct default_qos<msg::Image> : sensor_data_qos {};
template <> struct default_qos<msg::CompressedImage> : sensor_data_qos {};
template <> struct default_qos<msg::DepthImage> : sensor_data_qos {};
template <> struct default_qos<msg::PointCloud> : sensor_data_qos {};
template <> struct default_qos<msg::LaserScan> : sensor_data_qos {};
template <> struct default_qos<msg::Imu> : sensor_data_qos {};
template <> struct default_qos<msg::Tensor> : sensor_data_qos {};
template <> struct default_qos<msg::AudioFrame> : sensor_data_qos {};
template <> struct default_qos<msg::SegmentationMask> : sensor_data_qos {};
template <> struct default_qos<msg::OccupancyGrid> : latched_qos {};
template <> struct default_qos<msg::CostMap> : latched_qos {};

}  // namespace horus::net

HORUS_API_END
