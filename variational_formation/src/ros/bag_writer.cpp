// Our own writer of ROS bags, format 2.0 (bag_writer.hpp): the records rosbag writes, chunk by
// chunk, with no seek before each message.
#include "variational_formation/ros/bag_writer.hpp"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <stdexcept>

#include <lz4frame.h>

namespace vf {

namespace {

constexpr char kVersionLine[] = "#ROSBAG V2.0\n";
constexpr std::uint8_t kOpMessageData = 0x02, kOpFileHeader = 0x03, kOpIndexData = 0x04, kOpChunk = 0x05,
                       kOpChunkInfo = 0x06, kOpConnection = 0x07;
constexpr std::uint32_t kFileHeaderLength = 4096;  // the file header record's header and padding
constexpr std::uint32_t kIndexVersion = 1, kChunkInfoVersion = 1;

/// rosbag's LZ4 chunks are LZ4 frames as roslz4 reads them: blocks of at most 1 MB (rosbag's
/// block size id 6), independent, no block checksums, no content size, and a checksum of the
/// whole content. liblz4's frame writer makes the same frame roslz4's does, with the same
/// compressed blocks, about a tenth faster (its content checksum and no staging copy).
LZ4F_preferences_t lz4Frames() {
  LZ4F_preferences_t p;
  std::memset(&p, 0, sizeof p);
  p.frameInfo.blockSizeID = LZ4F_max1MB;
  p.frameInfo.blockMode = LZ4F_blockIndependent;
  p.frameInfo.contentChecksumFlag = LZ4F_contentChecksumEnabled;
  p.frameInfo.blockChecksumFlag = LZ4F_noBlockChecksum;
  p.frameInfo.contentSize = 0;
  p.compressionLevel = 0;  // LZ4's default (fast) mode, as roslz4's LZ4_compress_default
  return p;
}

void append(std::vector<std::uint8_t>& out, const void* bytes, std::size_t count) {
  const auto* b = static_cast<const std::uint8_t*>(bytes);
  out.insert(out.end(), b, b + count);
}
void appendU32(std::vector<std::uint8_t>& out, std::uint32_t v) { append(out, &v, 4); }
/// a < b, inline (ros::Time's operator< is a call into librostime, ~2 % of the recorder).
bool earlier(const ros::Time& a, const ros::Time& b) { return a.sec < b.sec || (a.sec == b.sec && a.nsec < b.nsec); }
void appendTime(std::vector<std::uint8_t>& out, const ros::Time& t) {
  appendU32(out, t.sec);
  appendU32(out, t.nsec);
}

/// A record's header (or a connection header): fields "name=value", each after its length.
class Fields {
 public:
  explicit Fields(std::vector<std::uint8_t>& out) : out_(out), start_(out.size()) { appendU32(out_, 0); }
  Fields& bytes(const char* name, const void* value, std::size_t count) {
    const std::size_t n = std::strlen(name);
    appendU32(out_, static_cast<std::uint32_t>(n + 1 + count));
    append(out_, name, n);
    out_.push_back('=');
    append(out_, value, count);
    return *this;
  }
  Fields& op(std::uint8_t v) { return bytes("op", &v, 1); }
  Fields& u32(const char* name, std::uint32_t v) { return bytes(name, &v, 4); }
  Fields& u64(const char* name, std::uint64_t v) { return bytes(name, &v, 8); }
  Fields& time(const char* name, const ros::Time& t) {
    const std::uint32_t v[2] = {t.sec, t.nsec};
    return bytes(name, v, 8);
  }
  Fields& text(const char* name, const std::string& v) { return bytes(name, v.data(), v.size()); }
  /// Writes the header's length in front of it; @return that length.
  std::uint32_t done() {
    const auto length = static_cast<std::uint32_t>(out_.size() - start_ - 4);
    std::memcpy(out_.data() + start_, &length, 4);
    return length;
  }

 private:
  std::vector<std::uint8_t>& out_;
  std::size_t start_;
};

}  // namespace

BagWriter::~BagWriter() {
  if (!isOpen()) return;
  try {
    close();
  } catch (const std::exception& e) {
    ROS_ERROR("%s", e.what());
  }
}

void BagWriter::failed(const std::string& what) const {
  throw std::runtime_error((path_.empty() ? std::string("bag") : path_) + ": " + what);
}

void BagWriter::open(const std::string& path, Compression compression, std::uint32_t chunkBytes,
                     double chunkSeconds) {
  if (isOpen()) failed("already open (writing " + path_ + ")");
  path_ = path;
  stream_ = std::fopen(path.c_str(), "wb");
  if (stream_ == nullptr) failed(std::strerror(errno));
  compression_ = compression;
  chunkBytes_ = std::max<std::uint32_t>(chunkBytes, 1);
  chunkAge_ = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(std::max(chunkSeconds, 0.0)));
  fileBytes_ = 0;
  static std::atomic<std::uint64_t> files{0};
  file_ = ++files;
  connections_.clear();
  byTopic_.clear();
  index_.clear();
  chunkConnections_.clear();
  chunks_.clear();
  chunk_.clear();
  chunk_.reserve(std::min<std::uint32_t>(chunkBytes_, 1024 * 1024) + 64 * 1024);  // a big limit grows as needed
  try {
    put(kVersionLine, sizeof(kVersionLine) - 1);
    writeFileHeader(0);  // rewritten at close with the index's position and the counts
    if (std::fflush(stream_) != 0) failed(std::strerror(errno));
  } catch (...) {
    std::fclose(stream_);
    stream_ = nullptr;
    throw;
  }
}

void BagWriter::writeFileHeader(std::uint64_t indexPosition) {
  record_.clear();
  const std::uint32_t length = Fields(record_)
                                   .op(kOpFileHeader)
                                   .u64("index_pos", indexPosition)
                                   .u32("conn_count", static_cast<std::uint32_t>(connections_.size()))
                                   .u32("chunk_count", static_cast<std::uint32_t>(chunks_.size()))
                                   .done();
  const std::uint32_t padding = length < kFileHeaderLength ? kFileHeaderLength - length : 0;
  appendU32(record_, padding);
  record_.insert(record_.end(), padding, ' ');
  put(record_.data(), record_.size());
}

std::uint32_t BagWriter::connection(const std::string& topic, const char* type, const char* md5sum,
                                    const char* definition) {
  const auto found = byTopic_.find(topic);
  if (found != byTopic_.end()) {
    const Connection& c = connections_[found->second];
    if (c.type != type) failed("topic " + topic + " was written as " + c.type + ", now as " + type);
    return found->second;
  }
  const auto id = static_cast<std::uint32_t>(connections_.size());
  connections_.push_back(Connection{topic, type, md5sum, definition});
  byTopic_.emplace(topic, id);
  index_.emplace_back();
  // Its connection record goes into the chunk that holds its first message, as rosbag does (so
  // `rosbag reindex` finds it), and again with the index at the end.
  appendConnectionRecord(chunk_, id);
  return id;
}

void BagWriter::appendConnectionRecord(std::vector<std::uint8_t>& out, std::uint32_t id) const {
  const Connection& c = connections_[id];
  Fields(out).op(kOpConnection).u32("conn", id).text("topic", c.topic).done();
  // Its data is the connection header, as rosbag writes it for a message written without one.
  Fields(out).text("topic", c.topic).text("type", c.type).text("md5sum", c.md5sum)
      .text("message_definition", c.definition).done();
}

void BagWriter::checkWritable(const std::string& topic, const ros::Time& time) const {
  if (!isOpen()) failed("not open");
  if (time.isZero()) failed("a message on " + topic + " at time 0 (a bag's times start at 1 ns)");
}

std::uint8_t* BagWriter::beginMessage(std::uint32_t conn, const ros::Time& time, std::uint32_t length) {
  if (chunkConnections_.empty()) {
    chunkStart_ = chunkEnd_ = time;
    chunkOpened_ = std::chrono::steady_clock::now();
    chunkMessages_ = 0;
  }
  if (index_[conn].empty()) chunkConnections_.push_back(conn);
  index_[conn].push_back(IndexEntry{time, static_cast<std::uint32_t>(chunk_.size())});
  if (earlier(time, chunkStart_)) chunkStart_ = time;
  if (earlier(chunkEnd_, time)) chunkEnd_ = time;
  // The record's header (what Fields writes: op, conn, time) and the data's length, in one append.
  struct __attribute__((packed)) MessageDataHeader {
    std::uint32_t headerLength = 38;
    std::uint32_t opLength = 4;
    char opName[3] = {'o', 'p', '='};
    std::uint8_t op = kOpMessageData;
    std::uint32_t connLength = 9;
    char connName[5] = {'c', 'o', 'n', 'n', '='};
    std::uint32_t conn;
    std::uint32_t timeLength = 13;
    char timeName[5] = {'t', 'i', 'm', 'e', '='};
    std::uint32_t sec, nsec;
    std::uint32_t dataLength;
  };
  static_assert(sizeof(MessageDataHeader) == 4 + 38 + 4, "a message data record's header and data length");
  MessageDataHeader header;
  header.conn = conn;
  header.sec = time.sec;
  header.nsec = time.nsec;
  header.dataLength = length;
  const std::size_t at = chunk_.size();
  chunk_.resize(at + sizeof header + length);
  std::memcpy(chunk_.data() + at, &header, sizeof header);
  return chunk_.data() + at + sizeof header;
}

void BagWriter::endMessage() {
  // The clock is read at every 16th message of a chunk: a step of the recorder writes 9 or more.
  if (chunk_.size() >= chunkBytes_ ||
      (++chunkMessages_ % 16 == 0 && std::chrono::steady_clock::now() - chunkOpened_ >= chunkAge_)) {
    writeChunk();
  }
}

void BagWriter::writeChunk() {
  if (chunkConnections_.empty()) return;
  const auto size = static_cast<std::uint32_t>(chunk_.size());
  const char* data = reinterpret_cast<const char*>(chunk_.data());
  std::uint32_t dataLength = size;
  std::string method = "none";
  if (compression_ == Compression::Lz4) {
    static const LZ4F_preferences_t frames = lz4Frames();
    compressed_.resize(LZ4F_compressFrameBound(size, &frames));
    const std::size_t out = LZ4F_compressFrame(compressed_.data(), compressed_.size(), chunk_.data(), size, &frames);
    // An error (none is expected with a buffer of the bound's size) writes the chunk plain.
    if (!LZ4F_isError(out)) {
      data = compressed_.data();
      dataLength = static_cast<std::uint32_t>(out);
      method = "lz4";
    }
  }
  ChunkInfo info;
  info.position = fileBytes_;
  info.start = chunkStart_;
  info.end = chunkEnd_;
  record_.clear();
  Fields(record_).op(kOpChunk).text("compression", method).u32("size", size).done();
  appendU32(record_, dataLength);
  put(record_.data(), record_.size());
  put(data, dataLength);
  // One index data record per connection in the chunk: (time, offset in the chunk) per message.
  record_.clear();
  for (const std::uint32_t conn : chunkConnections_) {
    std::vector<IndexEntry>& entries = index_[conn];
    const auto count = static_cast<std::uint32_t>(entries.size());
    Fields(record_).op(kOpIndexData).u32("ver", kIndexVersion).u32("conn", conn).u32("count", count).done();
    appendU32(record_, count * 12);
    for (const IndexEntry& e : entries) {
      appendTime(record_, e.time);
      appendU32(record_, e.offset);
    }
    info.counts.emplace_back(conn, count);
    entries.clear();
  }
  put(record_.data(), record_.size());
  // Into the file now: a writer killed later loses only the chunk it was filling.
  if (std::fflush(stream_) != 0) failed(std::strerror(errno));
  chunks_.push_back(std::move(info));
  chunkConnections_.clear();
  chunk_.clear();
}

void BagWriter::close() {
  if (!isOpen()) return;
  try {
    writeChunk();
    const std::uint64_t indexPosition = fileBytes_;
    record_.clear();
    for (std::uint32_t id = 0; id < connections_.size(); ++id) appendConnectionRecord(record_, id);
    for (const ChunkInfo& info : chunks_) {
      const auto count = static_cast<std::uint32_t>(info.counts.size());
      Fields(record_).op(kOpChunkInfo).u32("ver", kChunkInfoVersion).u64("chunk_pos", info.position)
          .time("start_time", info.start).time("end_time", info.end).u32("count", count).done();
      appendU32(record_, count * 8);
      for (const auto& [conn, messages] : info.counts) {
        appendU32(record_, conn);
        appendU32(record_, messages);
      }
    }
    put(record_.data(), record_.size());
    if (std::fseek(stream_, sizeof(kVersionLine) - 1, SEEK_SET) != 0) failed(std::strerror(errno));
    const std::uint64_t end = fileBytes_;
    writeFileHeader(indexPosition);
    fileBytes_ = end;
  } catch (...) {
    std::fclose(stream_);
    stream_ = nullptr;
    throw;
  }
  const int closed = std::fclose(stream_);
  stream_ = nullptr;
  if (closed != 0) failed(std::strerror(errno));
}

void BagWriter::put(const void* bytes, std::size_t count) {
  if (count > 0 && std::fwrite(bytes, 1, count, stream_) != count) failed(std::strerror(errno));
  fileBytes_ += count;
}

}  // namespace vf
