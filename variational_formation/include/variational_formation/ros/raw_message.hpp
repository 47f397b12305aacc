#pragma once

#include <cstdint>
#include <cstring>
#include <vector>

// boost::shared_ptr comes with roscpp (ros/forwards.h), as for every message type.
#include <ros/forwards.h>
#include <ros/message_traits.h>
#include <ros/serialization.h>

namespace vf {

/**
 * A message of type M kept as the bytes it came in: subscribed to as M (its type, MD5 sum and
 * definition), never deserialised, and written back byte for byte. The recorder takes the
 * monitor's marker arrays this way: it only stores them in the bag, and reading each array into
 * points and colours, then writing it out again, cost about 4 % of it (doc/benchmarks.md).
 */
template <class M>
struct RawMessage {
  using Ptr = boost::shared_ptr<RawMessage>;
  using ConstPtr = boost::shared_ptr<const RawMessage>;
  std::vector<std::uint8_t> bytes;  // M serialised
};

}  // namespace vf

namespace ros {
namespace message_traits {
template <class M>
struct MD5Sum<vf::RawMessage<M>> {
  static const char* value() { return MD5Sum<M>::value(); }
  static const char* value(const vf::RawMessage<M>&) { return value(); }
};
template <class M>
struct DataType<vf::RawMessage<M>> {
  static const char* value() { return DataType<M>::value(); }
  static const char* value(const vf::RawMessage<M>&) { return value(); }
};
template <class M>
struct Definition<vf::RawMessage<M>> {
  static const char* value() { return Definition<M>::value(); }
  static const char* value(const vf::RawMessage<M>&) { return value(); }
};
}  // namespace message_traits

namespace serialization {
template <class M>
struct Serializer<vf::RawMessage<M>> {
  template <typename Stream>
  inline static void write(Stream& stream, const vf::RawMessage<M>& m) {
    if (!m.bytes.empty()) std::memcpy(stream.advance(static_cast<uint32_t>(m.bytes.size())), m.bytes.data(), m.bytes.size());
  }
  /// The whole message: roscpp hands a subscriber's stream exactly one message.
  template <typename Stream>
  inline static void read(Stream& stream, vf::RawMessage<M>& m) {
    const uint32_t length = stream.getLength();
    const uint8_t* data = stream.advance(length);
    m.bytes.assign(data, data + length);
  }
  inline static uint32_t serializedLength(const vf::RawMessage<M>& m) { return static_cast<uint32_t>(m.bytes.size()); }
};
}  // namespace serialization
}  // namespace ros
