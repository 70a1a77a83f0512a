#include "duet/live/source_spec.h"

#include <gtest/gtest.h>

namespace duet {
namespace {

TEST(SourceSpec, Replay) {
  Result<SourceSpec> s = parse_source_spec("replay:/data/60_03.bvh?speed=1.5&loop=1&start=2");
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_EQ(s.value().kind, SourceKind::kReplay);
  EXPECT_EQ(s.value().path, "/data/60_03.bvh");
  EXPECT_DOUBLE_EQ(s.value().replay.speed, 1.5);
  EXPECT_TRUE(s.value().replay.loop);
  EXPECT_DOUBLE_EQ(s.value().replay.start_s, 2.0);
  Result<SourceSpec> plain = parse_source_spec("replay:a.bvh");
  ASSERT_TRUE(plain);
  EXPECT_DOUBLE_EQ(plain.value().replay.speed, 1.0);
  EXPECT_FALSE(plain.value().replay.loop);
  EXPECT_FALSE(parse_source_spec("replay:"));
  EXPECT_FALSE(parse_source_spec("replay:a.bvh?speed=0"));
  EXPECT_FALSE(parse_source_spec("replay:a.bvh?speed=fast"));
  EXPECT_FALSE(parse_source_spec("replay:a.bvh?loop=maybe"));
  EXPECT_FALSE(parse_source_spec("replay:a.bvh?colour=red"));
}

TEST(SourceSpec, Vmc) {
  Result<SourceSpec> port_only = parse_source_spec("vmc:39540");
  ASSERT_TRUE(port_only) << port_only.error().message;
  EXPECT_EQ(port_only.value().kind, SourceKind::kVmc);
  EXPECT_EQ(port_only.value().host, "127.0.0.1");
  EXPECT_EQ(port_only.value().port, 39540);
  Result<SourceSpec> plain = parse_source_spec("vmc");
  ASSERT_TRUE(plain) << plain.error().message;
  EXPECT_EQ(plain.value().port, kVmcDefaultPort);
  Result<SourceSpec> any = parse_source_spec("vmc:0.0.0.0:39539");
  ASSERT_TRUE(any);
  EXPECT_EQ(any.value().host, "0.0.0.0");
  Result<SourceSpec> v6 = parse_source_spec("vmc:[::1]:39539");
  ASSERT_TRUE(v6);
  EXPECT_EQ(v6.value().host, "::1");
  EXPECT_STREQ(source_kind_name(SourceKind::kVmc), "vmc");
  // Bad specs say what was expected.
  for (const char* bad : {"vmc:", "vmc:port", "vmc:0", "vmc:70000", "vmc:1.2.3.4:", "vmc:[::1]"}) {
    Result<SourceSpec> s = parse_source_spec(bad);
    ASSERT_FALSE(s) << bad;
    EXPECT_NE(s.error().message.find("expected vmc"), std::string::npos) << s.error().message;
    EXPECT_NE(s.error().message.find(bad), std::string::npos) << s.error().message;
  }
  Result<SourceSpec> option = parse_source_spec("vmc:39539?reference=1");
  ASSERT_FALSE(option);
  EXPECT_NE(option.error().message.find("vmc takes no options"), std::string::npos)
      << option.error().message;
}

TEST(SourceSpec, Neuron) {
  Result<SourceSpec> tcp = parse_source_spec("neuron-tcp:192.168.1.5:7001");
  ASSERT_TRUE(tcp) << tcp.error().message;
  EXPECT_EQ(tcp.value().kind, SourceKind::kNeuronTcp);
  EXPECT_EQ(tcp.value().host, "192.168.1.5");
  EXPECT_EQ(tcp.value().port, 7001);
  Result<SourceSpec> port_only = parse_source_spec("neuron-tcp:7001?reference=1");
  ASSERT_TRUE(port_only);
  EXPECT_EQ(port_only.value().host, "127.0.0.1");
  EXPECT_TRUE(port_only.value().reference);
  Result<SourceSpec> udp = parse_source_spec("neuron-udp:7002");
  ASSERT_TRUE(udp);
  EXPECT_EQ(udp.value().kind, SourceKind::kNeuronUdp);
  EXPECT_EQ(udp.value().host, "127.0.0.1");
  Result<SourceSpec> v6 = parse_source_spec("neuron-udp:[::]:7002");
  ASSERT_TRUE(v6);
  EXPECT_EQ(v6.value().host, "::");
  EXPECT_FALSE(parse_source_spec("neuron-tcp:"));
  EXPECT_FALSE(parse_source_spec("neuron-tcp:host:"));
  EXPECT_FALSE(parse_source_spec("neuron-tcp:host:70000"));
  EXPECT_FALSE(parse_source_spec("neuron-udp:0"));
  EXPECT_FALSE(parse_source_spec("neuron-udp:7002?speed=2"));
}

TEST(SourceSpec, WebSocketAndUnknown) {
  Result<SourceSpec> ws = parse_source_spec("ws");
  ASSERT_TRUE(ws);
  EXPECT_EQ(ws.value().kind, SourceKind::kWebSocket);
  EXPECT_TRUE(ws.value().path.empty());
  Result<SourceSpec> with_skeleton = parse_source_spec("ws:me.bvh");
  ASSERT_TRUE(with_skeleton);
  EXPECT_EQ(with_skeleton.value().path, "me.bvh");
  EXPECT_FALSE(parse_source_spec("ws:"));
  EXPECT_FALSE(parse_source_spec("kinect:1"));
  EXPECT_FALSE(parse_source_spec(""));
}

}  // namespace
}  // namespace duet
