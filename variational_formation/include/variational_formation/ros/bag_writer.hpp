#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <unordered_map>
#include <vector>

#include <ros/ros.h>

namespace vf {

/**
 * Writes a ROS bag, format 2.0 (the format of rosbag and `rosbag record`; doc/distributed.md,
 * "Recording"), for the recorder. rosbag::Bag seeks to the file's end twice before every message
 * it writes; glibc's fseeko on its read-write file then asks the file's size and re-reads the
 * last block, and at 100 agents that capped a recorded run near 1500 steps/s (doc/benchmarks.md).
 * This writer builds each chunk in memory and writes it whole, with its index, in one go; a
 * message costs its serialisation and a few appends, and no system call.
 *
 * The file is the one rosbag writes: the version line, a file header record padded to 4096
 * bytes (rewritten at close with the index's position and counts), chunks (each holding the
 * connection records of its new topics and the message data records, LZ4-compressed or not)
 * each followed by one index data record per topic in it, then the connection records and one
 * chunk info record per chunk. rosbag (C++ and Python), `rosbag info`, `rosbag play` and
 * `rosbag reindex` read it. Messages must come in time order per topic, as rosbag's readers
 * assume of a recording; the recorder writes whole steps in order.
 *
 * Not thread-safe. Errors throw std::runtime_error, one line: "<path>: <what went wrong>".
 */
class BagWriter {
 public:
  enum class Compression { None, Lz4 };

  BagWriter() = default;
  BagWriter(const BagWriter&) = delete;
  BagWriter& operator=(const BagWriter&) = delete;
  /// Closes the bag if it is open (errors are then only logged).
  ~BagWriter();

  /// Creates (or truncates) `path`. A chunk is written once it holds `chunkBytes` bytes or more
  /// (uncompressed; at least 1), or once it has been open `chunkSeconds` of wall time (the age
  /// is looked at every 16th message): a killed writer loses about its last chunkSeconds.
  void open(const std::string& path, Compression compression, std::uint32_t chunkBytes, double chunkSeconds = 1.0);
  bool isOpen() const { return stream_ != nullptr; }

  /// A topic named once, for writing to it without looking its name up at every message: its
  /// connection in the open file is kept with it (and found again in a new file).
  class Topic {
   public:
    explicit Topic(std::string name = "") : name_(std::move(name)) {}
    const std::string& name() const { return name_; }

   private:
    friend class BagWriter;
    std::string name_;
    std::uint64_t file_ = 0;         // the file its connection belongs to (BagWriter::file_; 0: none)
    const char* type_ = nullptr;     // the type it was written as there
    std::uint32_t connection_ = 0;
  };

  /// Appends `msg` on `topic` at bag time `time` (> 0). A topic keeps the type it was first
  /// written with.
  template <typename M>
  void write(Topic& topic, const ros::Time& time, const M& msg) {
    const std::uint32_t length = ros::serialization::serializationLength(msg);
    const char* type = ros::message_traits::datatype(msg);
    checkWritable(topic.name_, time);
    if (topic.file_ != file_ || topic.type_ != type) {
      topic.connection_ = connection(topic.name_, type, ros::message_traits::md5sum(msg),
                                     ros::message_traits::definition(msg));
      topic.file_ = file_;
      topic.type_ = type;
    }
    std::uint8_t* data = beginMessage(topic.connection_, time, length);
    ros::serialization::OStream stream(data, length);
    ros::serialization::serialize(stream, msg);
    endMessage();
  }
  /// The same, naming the topic (looked up by name at every message).
  template <typename M>
  void write(const std::string& topic, const ros::Time& time, const M& msg) {
    Topic named(topic);
    write(named, time, msg);
  }

  /// Bytes in the file so far: the chunk being filled is not counted until it is written, so a
  /// file held to a size by its writer ends at most a chunk past it (as with rosbag's LZ4 bags).
  std::uint64_t size() const { return fileBytes_; }
  /// Writes the open chunk, the index and the header, and closes the file.
  void close();

 private:
  struct Connection {
    std::string topic, type, md5sum, definition;
  };
  struct IndexEntry {
    ros::Time time;
    std::uint32_t offset;  // of the message data record in the uncompressed chunk
  };
  struct ChunkInfo {
    std::uint64_t position = 0;
    ros::Time start, end;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> counts;  // (connection, messages)
  };

  /// Throws unless the bag is open and `time` is a bag time (> 0).
  void checkWritable(const std::string& topic, const ros::Time& time) const;
  std::uint32_t connection(const std::string& topic, const char* type, const char* md5sum, const char* definition);
  /// Appends connection `id`'s record (in its first chunk, and again in the index at the end).
  void appendConnectionRecord(std::vector<std::uint8_t>& out, std::uint32_t id) const;
  /// Starts a message data record of connection `conn` in the chunk, and returns where its
  /// `length` bytes go.
  std::uint8_t* beginMessage(std::uint32_t conn, const ros::Time& time, std::uint32_t length);
  void endMessage();
  void writeChunk();
  void writeFileHeader(std::uint64_t indexPosition);
  /// Writes `bytes` to the file, or throws.
  void put(const void* bytes, std::size_t count);
  [[noreturn]] void failed(const std::string& what) const;

  std::FILE* stream_ = nullptr;
  /// The open file, numbered across every writer of the process (0: none), so that a Topic's
  /// connection is used only in the file it was found in.
  std::uint64_t file_ = 0;
  std::string path_;
  Compression compression_ = Compression::Lz4;
  std::uint32_t chunkBytes_ = 768 * 1024;
  std::chrono::steady_clock::duration chunkAge_{};
  std::chrono::steady_clock::time_point chunkOpened_;
  std::uint32_t chunkMessages_ = 0;
  std::uint64_t fileBytes_ = 0;
  std::vector<Connection> connections_;
  std::unordered_map<std::string, std::uint32_t> byTopic_;
  // The open chunk: its bytes, its time span and each connection's index entries.
  std::vector<std::uint8_t> chunk_;
  ros::Time chunkStart_, chunkEnd_;
  std::vector<std::vector<IndexEntry>> index_;  // by connection
  std::vector<std::uint32_t> chunkConnections_;  // connections with entries, in first-use order
  std::vector<ChunkInfo> chunks_;
  std::vector<char> compressed_;
  std::vector<std::uint8_t> record_;  // a record being assembled for the file
};

}  // namespace vf
