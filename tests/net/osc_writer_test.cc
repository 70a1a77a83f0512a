// The OSC bundles of --osc-out, decoded by liblo (a reference implementation).
#include "duet/net/osc_writer.h"

#include <gtest/gtest.h>
#include <lo/lo.h>

#include <array>
#include <cstring>
#include <string>
#include <vector>

#include "net/lo_args.h"

namespace duet::net {
namespace {

using test_osc::arg_float;
using test_osc::arg_int;
using test_osc::arg_string;

struct Decoded {
  std::vector<std::string> paths;
  std::vector<std::string> types;
  std::vector<std::vector<double>> numbers;
  std::vector<std::string> strings;
};

int collect(const char* path, const char* types, lo_arg** argv, int argc, lo_message, void* user) {
  auto* d = static_cast<Decoded*>(user);
  d->paths.push_back(path);
  d->types.push_back(types);
  std::vector<double> values;
  for (int k = 0; k < argc; ++k) {
    if (types[k] == 'i') values.push_back(arg_int(argv[k]));
    if (types[k] == 'f') values.push_back(arg_float(argv[k]));
    if (types[k] == 's') d->strings.push_back(arg_string(argv[k]));
  }
  d->numbers.push_back(values);
  return 0;
}

TEST(OscBundleWriter, LibloReadsWhatItWrites) {
  OscBundleWriter w(512);
  w.begin();
  const std::array<std::int32_t, 2> ints = {-7, 123456};
  const std::array<float, 1> floats = {0.625f};
  const std::array<std::string_view, 1> strings = {"01"};
  ASSERT_TRUE(w.message("/duet/take", "i", std::span(ints).first(1)));
  ASSERT_TRUE(w.message("/duet/take/name", "s", {}, {}, strings));
  ASSERT_TRUE(w.message("/duet/confidence", "f", {}, floats));
  ASSERT_TRUE(w.message("/duet/pair", "ii", ints));
  ASSERT_TRUE(w.ok());

  lo_server server = lo_server_new_with_proto(nullptr, LO_UDP, nullptr);
  ASSERT_NE(server, nullptr);
  Decoded d;
  lo_server_add_method(server, nullptr, nullptr, collect, &d);
  std::vector<char> bytes(w.bytes().begin(), w.bytes().end());
  EXPECT_EQ(lo_server_dispatch_data(server, bytes.data(), bytes.size()),
            static_cast<int>(bytes.size()));
  lo_server_free(server);
  ASSERT_EQ(d.paths.size(), 4u);
  EXPECT_EQ(d.paths[0], "/duet/take");
  EXPECT_EQ(d.numbers[0], std::vector<double>{-7});
  EXPECT_EQ(d.paths[1], "/duet/take/name");
  ASSERT_EQ(d.strings.size(), 1u);
  EXPECT_EQ(d.strings[0], "01");
  EXPECT_EQ(d.numbers[2], std::vector<double>{0.625});
  EXPECT_EQ(d.types[3], "ii");
  EXPECT_EQ(d.numbers[3], (std::vector<double>{-7, 123456}));
}

TEST(OscBundleWriter, TooSmallOrBadTypesFailsCleanly) {
  OscBundleWriter w(40);
  w.begin();
  const std::array<std::int32_t, 1> one = {1};
  EXPECT_TRUE(w.message("/a", "i", one));
  EXPECT_FALSE(w.message("/a/much/longer/address", "i", one));
  EXPECT_FALSE(w.ok());
  EXPECT_LE(w.bytes().size(), 40u);
  w.begin();
  EXPECT_FALSE(w.message("/a", "i"));  // an 'i' without its value
  w.begin();
  EXPECT_FALSE(w.message("/a", "q", one));  // a type Duet does not write
  w.begin();
  EXPECT_TRUE(w.ok());
}

}  // namespace
}  // namespace duet::net
