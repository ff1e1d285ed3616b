// Reads the messages of a rosbag::View into one reused message object instead of a freshly
// allocated one per message (rosbag::MessageInstance::instantiate makes a boost::shared_ptr, and the
// message's strings and arrays, for every message). The serialised bytes are copied from the bag's
// decompressed chunk into a buffer kept across messages, then deserialised in place: no heap
// allocation per message once the buffer and the message have grown to their working size.
// Used by hrg_bag and by the bag-reading floor benchmark, so both measure the same reading path.
#pragma once

#include <ros/serialization.h>
#include <rosbag/message_instance.h>

#include <cstdint>
#include <string>
#include <vector>

namespace hrg_gyro {
namespace bag_tools {

template <class Message>
class ReusedMessageReader {
 public:
  /// Deserialises `instance` into `*message`. False (message untouched) when the instance's
  /// connection carries another message type (another MD5 sum), as instantiate's null pointer.
  /// A record shorter than the message it claims to hold throws ros::serialization::StreamOverrunException.
  bool read(const rosbag::MessageInstance& instance, Message* message) {
    // The MD5 check once per connection, not per message: the sum is a string of the
    // connection's, the same object for all its messages.
    const std::string& md5sum = instance.getMD5Sum();
    if (&md5sum != checked_md5sum_) {
      checked_md5sum_ = &md5sum;
      connection_matches_ = md5sum == ros::message_traits::md5sum<Message>() || md5sum == "*";
    }
    if (!connection_matches_) return false;
    bytes_.clear();
    instance.write(*this);
    ros::serialization::IStream stream(bytes_.data(), static_cast<std::uint32_t>(bytes_.size()));
    ros::serialization::deserialize(stream, *message);
    return true;
  }

  /// The output-stream interface rosbag::MessageInstance::write fills (it copies the record's
  /// bytes to the pointer returned).
  std::uint8_t* advance(std::uint32_t length) {
    const std::size_t at = bytes_.size();
    bytes_.resize(at + length);
    return bytes_.data() + at;
  }

 private:
  std::vector<std::uint8_t> bytes_;
  const std::string* checked_md5sum_ = nullptr;
  bool connection_matches_ = false;
};

}  // namespace bag_tools
}  // namespace hrg_gyro
