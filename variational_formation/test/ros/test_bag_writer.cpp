// The recorder's bag writer (src/ros/bag_writer.cpp), read back by rosbag's own C++ reader: every
// message, topic, time, type and definition as written, through the index (by topic and by time),
// compressed or not, in one chunk or many; topics named once, in one file and the next; messages
// kept as bytes (RawMessage) written byte for byte; and a bad use is one line naming the file.
#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <sys/resource.h>

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <std_msgs/String.h>
#include <tf2_msgs/TFMessage.h>
#include <visualization_msgs/MarkerArray.h>

#include "variational_formation/ros/bag_writer.hpp"
#include "variational_formation/ros/raw_message.hpp"
#include "variational_formation/ros/recorder_node.hpp"
#include "variational_formation_msgs/AgentState.h"

namespace vf {
namespace {

using variational_formation_msgs::AgentState;
namespace fs = std::filesystem;

struct Written {
  std::string topic;
  ros::Time time;
  AgentState state;  // for the agents' topics
  std::string text;  // for /text
};

class BagWriterTest : public ::testing::TestWithParam<std::tuple<BagWriter::Compression, std::uint32_t>> {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("vf_bag_writer_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  /// `steps` steps of 3 agents' states, a /tf holding their frames and, every 10th step, a text.
  std::vector<Written> writeRun(BagWriter& bag, int steps) {
    std::vector<Written> out;
    for (int k = 0; k < steps; ++k) {
      const ros::Time t = std::max(ros::Time(0.005 * k), ros::TIME_MIN);
      tf2_msgs::TFMessage tf;
      for (int i = 0; i < 3; ++i) {
        AgentState s;
        s.header.stamp = t;
        s.header.frame_id = "agent_" + std::to_string(i);
        s.id = static_cast<std::uint32_t>(i);
        s.step = k;
        s.position = {0.1 * k + i, -0.25 * i, 1e-17 * k};
        const std::string topic = "/agent_" + std::to_string(i) + "/state";
        bag.write(topic, t, s);
        out.push_back(Written{topic, t, s, ""});
        tf.transforms.emplace_back();
        tf.transforms.back().child_frame_id = s.header.frame_id;
      }
      bag.write("/tf", t, tf);
      out.push_back(Written{"/tf", t, {}, ""});
      if (k % 10 == 0) {
        std_msgs::String text;
        text.data = std::string(static_cast<std::size_t>(k), 'x');
        bag.write("/text", t, text);
        out.push_back(Written{"/text", t, {}, text.data});
      }
    }
    return out;
  }

  fs::path dir_;
};

TEST_P(BagWriterTest, RosbagReadsBackEveryMessageAsWritten) {
  const auto [compression, chunkBytes] = GetParam();
  BagWriter bag;
  bag.open(path("run.bag"), compression, chunkBytes);
  const std::vector<Written> written = writeRun(bag, 300);
  bag.close();
  EXPECT_EQ(bag.size(), fs::file_size(path("run.bag")));

  rosbag::Bag in(path("run.bag"), rosbag::bagmode::Read);
  rosbag::View all(in);
  ASSERT_EQ(all.size(), written.size());
  // rosbag's view orders by time (a step's messages share one): each topic in the order written.
  std::map<std::string, std::vector<const Written*>> byTopic;
  for (const Written& w : written) byTopic[w.topic].push_back(&w);
  std::map<std::string, std::size_t> next;
  ros::Time last;
  std::size_t i = 0;
  for (const rosbag::MessageInstance& m : all) {
    ++i;
    ASSERT_TRUE(byTopic.count(m.getTopic())) << m.getTopic();
    ASSERT_LT(next[m.getTopic()], byTopic[m.getTopic()].size()) << m.getTopic();
    const Written& w = *byTopic[m.getTopic()][next[m.getTopic()]++];
    EXPECT_EQ(m.getTime(), w.time) << "message " << i;
    EXPECT_GE(m.getTime(), last) << "message " << i;
    last = m.getTime();
    if (w.topic == "/tf") {
      EXPECT_EQ(m.getDataType(), "tf2_msgs/TFMessage");
      EXPECT_EQ(m.getMD5Sum(), ros::message_traits::md5sum<tf2_msgs::TFMessage>());
      auto tf = m.instantiate<tf2_msgs::TFMessage>();
      ASSERT_TRUE(tf);
      EXPECT_EQ(tf->transforms.size(), 3u);
    } else if (w.topic == "/text") {
      auto text = m.instantiate<std_msgs::String>();
      ASSERT_TRUE(text);
      EXPECT_EQ(text->data, w.text);
    } else {
      EXPECT_EQ(m.getDataType(), "variational_formation_msgs/AgentState");
      EXPECT_EQ(m.getMessageDefinition(), ros::message_traits::definition<AgentState>());
      auto s = m.instantiate<AgentState>();
      ASSERT_TRUE(s);
      EXPECT_EQ(*s, w.state) << "message " << i;  // bit for bit: the doubles included
    }
  }
  for (const auto& [topic, list] : byTopic) EXPECT_EQ(next[topic], list.size()) << topic;
  // The index by topic and by time: one agent's states between two times.
  rosbag::View some(in, rosbag::TopicQuery("/agent_1/state"), ros::Time(0.5), ros::Time(1.0));
  std::vector<long> steps;
  for (const rosbag::MessageInstance& m : some) steps.push_back(m.instantiate<AgentState>()->step);
  ASSERT_EQ(steps.size(), 101u);  // t = 0.5 .. 1.0 s, both ends included
  for (std::size_t j = 0; j < steps.size(); ++j) EXPECT_EQ(steps[j], 100 + static_cast<long>(j));
  EXPECT_EQ(all.getBeginTime(), ros::TIME_MIN);
  EXPECT_EQ(all.getEndTime(), ros::Time(0.005 * 299));
  in.close();
}

// One chunk for the whole run, chunks of about 2 kB (a few steps each), a chunk per message.
INSTANTIATE_TEST_SUITE_P(Chunks, BagWriterTest,
                         ::testing::Combine(::testing::Values(BagWriter::Compression::None,
                                                              BagWriter::Compression::Lz4),
                                            ::testing::Values(768u * 1024u, 2000u, 1u)));

class BagWriterUse : public BagWriterTest {};

TEST_F(BagWriterUse, AnEmptyBagIsABagWithNoMessages) {
  BagWriter bag;
  bag.open(path("empty.bag"), BagWriter::Compression::Lz4, 1000);
  bag.close();
  rosbag::Bag in(path("empty.bag"), rosbag::bagmode::Read);
  EXPECT_EQ(rosbag::View(in).size(), 0u);
}

TEST_F(BagWriterUse, Lz4ChunksAreSmallerThanPlainOnes) {
  std::uintmax_t bytes[2] = {0, 0};
  for (const auto compression : {BagWriter::Compression::None, BagWriter::Compression::Lz4}) {
    const std::string file = path(compression == BagWriter::Compression::None ? "none.bag" : "lz4.bag");
    BagWriter bag;
    bag.open(file, compression, 768 * 1024);
    writeRun(bag, 300);
    bag.close();
    bytes[compression == BagWriter::Compression::Lz4] = fs::file_size(file);
  }
  // The run's names and headers repeat from step to step; a plain chunk would be as large.
  EXPECT_LT(static_cast<double>(bytes[1]), 0.6 * static_cast<double>(bytes[0])) << bytes[1] << " " << bytes[0];
}

TEST_F(BagWriterUse, AChunkLargerThanAnLz4BlockIsReadBackWhole) {
  // LZ4 frames hold blocks of at most 1 MB: a 3.5 MB chunk spans four, the last one short.
  BagWriter bag;
  bag.open(path("large.bag"), BagWriter::Compression::Lz4, 8u << 20);
  std::vector<std_msgs::String> texts(7);
  for (std::size_t k = 0; k < texts.size(); ++k) {
    texts[k].data.resize(500 * 1000 + k);
    for (std::size_t c = 0; c < texts[k].data.size(); ++c) texts[k].data[c] = static_cast<char>('a' + (c * c + k) % 23);
    bag.write("/text", ros::Time(static_cast<double>(k + 1)), texts[k]);
  }
  bag.close();
  EXPECT_LT(fs::file_size(path("large.bag")), 3500u * 1000u);  // compressed
  rosbag::Bag in(path("large.bag"), rosbag::bagmode::Read);
  std::size_t k = 0;
  for (const rosbag::MessageInstance& m : rosbag::View(in)) {
    const auto text = m.instantiate<std_msgs::String>();
    ASSERT_NE(text, nullptr);
    ASSERT_LT(k, texts.size());
    EXPECT_EQ(text->data, texts[k].data) << "message " << k;
    ++k;
  }
  EXPECT_EQ(k, texts.size());
}

TEST_F(BagWriterUse, ChunksOlderThanTheirAgeAreWrittenBeforeTheyFill) {
  BagWriter bag;
  bag.open(path("age.bag"), BagWriter::Compression::None, 1u << 30, 0.0);
  std_msgs::String text;
  text.data = "0123456789";
  for (int k = 1; k <= 128; ++k) bag.write("/text", ros::Time(k), text);
  // Chunks of age 0 go out at every 16th message: the file holds all 128 before the close.
  EXPECT_EQ(fs::file_size(path("age.bag")), bag.size());
  EXPECT_GT(bag.size(), 4096u + 128u * (10u + 4u + 4u + 38u));
  bag.close();
  rosbag::Bag in(path("age.bag"), rosbag::bagmode::Read);
  EXPECT_EQ(rosbag::View(in).size(), 128u);
}

TEST_F(BagWriterUse, ATopicNamedOnceIsFoundAgainInTheNextFile) {
  // As the recorder writes its split parts: one Topic per stream, bags opened one after another.
  BagWriter bag;
  BagWriter::Topic state("/agent_0/state"), text("/text");
  std_msgs::String t;
  for (int part = 0; part < 2; ++part) {
    bag.open(path("part" + std::to_string(part) + ".bag"), BagWriter::Compression::Lz4, 64);
    for (int k = 1; k <= 20; ++k) {
      AgentState s;
      s.step = 100 * part + k;
      s.position = {1.0 * k, 2.0, 3.0};
      bag.write(state, ros::Time(k), s);
      t.data = std::to_string(s.step);
      bag.write(text, ros::Time(k), t);
    }
    bag.close();
  }
  for (int part = 0; part < 2; ++part) {
    rosbag::Bag in(path("part" + std::to_string(part) + ".bag"), rosbag::bagmode::Read);
    rosbag::View states(in, rosbag::TopicQuery("/agent_0/state"));
    rosbag::View texts(in, rosbag::TopicQuery("/text"));
    ASSERT_EQ(states.size(), 20u);
    ASSERT_EQ(texts.size(), 20u);
    long k = 1;
    for (const rosbag::MessageInstance& m : states) {
      const auto s = m.instantiate<AgentState>();
      ASSERT_NE(s, nullptr);
      EXPECT_EQ(s->step, 100 * part + k);
      EXPECT_EQ(m.getTime(), ros::Time(static_cast<double>(k)));
      ++k;
    }
    k = 1;
    for (const rosbag::MessageInstance& m : texts) {
      const auto s = m.instantiate<std_msgs::String>();
      ASSERT_NE(s, nullptr);
      EXPECT_EQ(s->data, std::to_string(100 * part + k++));
    }
  }
  // One Topic in two writers at once, whose connections are numbered in opposite orders.
  BagWriter first, second;
  first.open(path("first.bag"), BagWriter::Compression::None, 1000);
  second.open(path("second.bag"), BagWriter::Compression::None, 1000);
  t.data = "a";
  first.write(text, ros::Time(1), t);
  second.write(state, ros::Time(1), AgentState());
  second.write(text, ros::Time(2), t);
  first.write(state, ros::Time(2), AgentState());
  first.close();
  second.close();
  for (const char* name : {"first.bag", "second.bag"}) {
    rosbag::Bag in(path(name), rosbag::bagmode::Read);
    EXPECT_EQ(rosbag::View(in, rosbag::TopicQuery("/text")).size(), 1u) << name;
    for (const rosbag::MessageInstance& m : rosbag::View(in, rosbag::TopicQuery("/text"))) {
      EXPECT_NE(m.instantiate<std_msgs::String>(), nullptr) << name;
    }
    for (const rosbag::MessageInstance& m : rosbag::View(in, rosbag::TopicQuery("/agent_0/state"))) {
      EXPECT_NE(m.instantiate<AgentState>(), nullptr) << name;
    }
  }
  // A Topic keeps its type's check: written as another type, it fails as by name.
  bag.open(path("typed.bag"), BagWriter::Compression::None, 1000);
  bag.write(text, ros::Time(1), t);
  try {
    bag.write(text, ros::Time(2), AgentState());
    FAIL() << "a topic changed its type";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              path("typed.bag") + ": topic /text was written as std_msgs/String, now as variational_formation_msgs/AgentState");
  }
  bag.close();
}

TEST_F(BagWriterUse, AMessageKeptAsBytesIsWrittenByteForByteAsItsType) {
  // As roscpp hands a subscriber its message: one serialised message in a stream.
  visualization_msgs::MarkerArray markers;
  for (int i = 0; i < 3; ++i) {
    visualization_msgs::Marker m;
    m.header.stamp = ros::Time(12, 345678901 + i);
    m.header.frame_id = "world";
    m.ns = "ns" + std::to_string(i);
    m.type = visualization_msgs::Marker::LINE_LIST;
    m.points.resize(static_cast<std::size_t>(4 * i));
    for (std::size_t p = 0; p < m.points.size(); ++p) m.points[p].x = 0.5 * static_cast<double>(p) + i;
    m.text = "step " + std::to_string(i);
    markers.markers.push_back(m);
  }
  const std::uint32_t length = ros::serialization::serializationLength(markers);
  std::vector<std::uint8_t> wire(length);
  ros::serialization::OStream out(wire.data(), length);
  ros::serialization::serialize(out, markers);
  RawMessage<visualization_msgs::MarkerArray> raw;
  ros::serialization::IStream in(wire.data(), length);
  ros::serialization::deserialize(in, raw);
  EXPECT_EQ(raw.bytes, wire);
  EXPECT_STREQ(ros::message_traits::md5sum(raw), ros::message_traits::md5sum(markers));
  EXPECT_STREQ(ros::message_traits::datatype(raw), "visualization_msgs/MarkerArray");
  // The recorder reads the step's stamp from the bytes: the first marker's, none when empty.
  EXPECT_EQ(RecorderNode::markersStamp(raw), ros::Time(12, 345678901));
  EXPECT_EQ(RecorderNode::markersStamp(RawMessage<visualization_msgs::MarkerArray>{{0, 0, 0, 0}}), ros::TIME_MIN);
  EXPECT_EQ(RecorderNode::markersStamp(RawMessage<visualization_msgs::MarkerArray>{{1, 0, 0, 0, 7}}), ros::TIME_MIN);

  BagWriter bag;
  bag.open(path("raw.bag"), BagWriter::Compression::Lz4, 1000);
  bag.write("/markers", ros::Time(1), raw);
  bag.close();
  rosbag::Bag bagIn(path("raw.bag"), rosbag::bagmode::Read);
  rosbag::View view(bagIn);
  ASSERT_EQ(view.size(), 1u);
  const rosbag::View::iterator first = view.begin();
  const rosbag::MessageInstance& m = *first;
  EXPECT_EQ(m.getDataType(), "visualization_msgs/MarkerArray");
  EXPECT_EQ(m.getMessageDefinition(), ros::message_traits::definition(markers));
  const auto back = m.instantiate<visualization_msgs::MarkerArray>();
  ASSERT_NE(back, nullptr);
  std::vector<std::uint8_t> again(ros::serialization::serializationLength(*back));
  ros::serialization::OStream out2(again.data(), static_cast<std::uint32_t>(again.size()));
  ros::serialization::serialize(out2, *back);
  EXPECT_EQ(again, wire);
}

TEST_F(BagWriterUse, BadUsesAreOneLineNamingTheFile) {
  const auto message = [](auto&& f) {
    try {
      f();
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  BagWriter bag;
  EXPECT_EQ(message([&] { bag.open("/nonexistent/dir/x.bag", BagWriter::Compression::Lz4, 1000); }),
            "/nonexistent/dir/x.bag: No such file or directory");
  EXPECT_FALSE(bag.isOpen());
  std_msgs::String text;
  EXPECT_EQ(message([&] { bag.write("/text", ros::Time(1), text); }), "/nonexistent/dir/x.bag: not open");

  bag.open(path("bad.bag"), BagWriter::Compression::Lz4, 1000);
  EXPECT_EQ(message([&] { bag.write("/text", ros::Time(0), text); }),
            path("bad.bag") + ": a message on /text at time 0 (a bag's times start at 1 ns)");
  bag.write("/text", ros::Time(1), text);
  AgentState s;
  EXPECT_EQ(message([&] { bag.write("/text", ros::Time(2), s); }),
            path("bad.bag") + ": topic /text was written as std_msgs/String, now as variational_formation_msgs/AgentState");
  EXPECT_EQ(message([&] { bag.open(path("other.bag"), BagWriter::Compression::Lz4, 1000); }),
            path("bad.bag") + ": already open (writing " + path("bad.bag") + ")");
  bag.close();
  EXPECT_EQ(message([&] { bag.close(); }), "no error");  // a second close does nothing
  // The bag holds what was written before the bad uses.
  rosbag::Bag in(path("bad.bag"), rosbag::bagmode::Read);
  EXPECT_EQ(rosbag::View(in).size(), 1u);
}

TEST_F(BagWriterUse, AFullDiskIsOneLineAndLeavesNothingOpen) {
  BagWriter bag;
  try {
    bag.open("/dev/full", BagWriter::Compression::None, 1);
    FAIL() << "a full disk went unnoticed";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "/dev/full: No space left on device");
  }
  EXPECT_FALSE(bag.isOpen());
}

TEST_F(BagWriterUse, AFileThatCannotGrowIsOneLineAndTheChunksBeforeItStayReadable) {
  // A real limit on the file's size (RLIMIT_FSIZE, as `ulimit -f`): the write that crosses it
  // fails with EFBIG (SIGXFSZ ignored), in the middle of the run.
  std::signal(SIGXFSZ, SIG_IGN);
  rlimit before{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &before), 0);
  rlimit limit = before;
  limit.rlim_cur = 64 * 1024;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limit), 0);
  BagWriter bag;
  bag.open(path("limited.bag"), BagWriter::Compression::None, 4096);
  std_msgs::String text;
  text.data = std::string(1000, 'y');
  std::string error;
  int written = 0;
  try {
    for (int k = 1; k <= 1000; ++k, ++written) bag.write("/text", ros::Time(k), text);
  } catch (const std::runtime_error& e) {
    error = e.what();
  }
  EXPECT_THROW(bag.close(), std::runtime_error);  // its index cannot be written either
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &before), 0);
  std::signal(SIGXFSZ, SIG_DFL);
  EXPECT_EQ(error, path("limited.bag") + ": File too large");
  EXPECT_GT(written, 40);
  EXPECT_LT(written, 70);
  EXPECT_FALSE(bag.isOpen());
  // Without its index the file is what a killed recorder leaves: rosbag refuses it, and
  // `rosbag reindex` recovers every whole chunk (4 messages each here) written before the failure.
  EXPECT_THROW(rosbag::Bag(path("limited.bag"), rosbag::bagmode::Read), rosbag::BagException);
  ASSERT_EQ(std::system(("rosbag reindex --quiet " + path("limited.bag") + " >/dev/null 2>&1").c_str()), 0);
  rosbag::Bag in(path("limited.bag"), rosbag::bagmode::Read);
  const auto recovered = static_cast<int>(rosbag::View(in).size());
  EXPECT_LE(recovered, written);
  EXPECT_GE(recovered, written - 8);
}

}  // namespace
}  // namespace vf
