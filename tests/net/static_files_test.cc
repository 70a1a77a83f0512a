#include "duet/net/static_files.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

namespace duet::net {
namespace {

namespace fs = std::filesystem;

class StaticFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    base_ = fs::temp_directory_path() / ("duet-static-" + std::to_string(::getpid()));
    fs::remove_all(base_);
    fs::create_directories(base_ / "web" / "assets");
    fs::create_directories(base_ / "web" / "empty");
    std::ofstream(base_ / "web" / "index.html") << "index";
    std::ofstream(base_ / "web" / "assets" / "app.js") << "js";
    std::ofstream(base_ / "web" / "a b.txt") << "space";
    std::ofstream(base_ / "secret.txt") << "secret";
    fs::create_symlink(base_ / "secret.txt", base_ / "web" / "out.txt");
    fs::create_symlink(base_ / "web" / "assets" / "app.js", base_ / "web" / "in.js");
    root_ = canonical_web_root(base_ / "web").value();
  }
  void TearDown() override { fs::remove_all(base_); }

  StaticLookup lookup(std::string_view target) { return find_static_file(root_, target).status; }

  fs::path base_, root_;
};

TEST_F(StaticFiles, FindsFilesAndIndexes) {
  EXPECT_EQ(find_static_file(root_, "/").path, root_ / "index.html");
  EXPECT_EQ(find_static_file(root_, "/assets/app.js?v=1#top").path, root_ / "assets" / "app.js");
  EXPECT_EQ(find_static_file(root_, "//assets//app.js").path, root_ / "assets" / "app.js");
  EXPECT_EQ(find_static_file(root_, "/a%20b.txt").path, root_ / "a b.txt");
  EXPECT_EQ(lookup("/in.js"), StaticLookup::kFound);  // a link that stays inside
  EXPECT_EQ(lookup("/missing.html"), StaticLookup::kNotFound);
  EXPECT_EQ(lookup("/empty/"), StaticLookup::kNotFound);
  EXPECT_EQ(lookup("/out.txt"), StaticLookup::kNotFound);  // a link that leads outside
}

TEST_F(StaticFiles, RefusesEscapes) {
  for (const char* target :
       {"/../secret.txt", "/assets/../../secret.txt", "/%2e%2e/secret.txt", "/%2E%2E%2Fsecret.txt",
        "/..%2Fsecret.txt", "/./index.html", "/a%00b", "/%zz", "/%2", "/assets\\..\\index.html",
        "index.html", "", "/assets/.."}) {
    EXPECT_EQ(lookup(target), StaticLookup::kBadTarget) << target;
  }
  EXPECT_EQ(lookup(std::string(5000, '/')), StaticLookup::kBadTarget);
}

TEST_F(StaticFiles, ContentTypes) {
  EXPECT_EQ(content_type_for("index.html"), "text/html; charset=utf-8");
  EXPECT_EQ(content_type_for("x/APP.JS"), "text/javascript; charset=utf-8");
  EXPECT_EQ(content_type_for("a.mjs"), "text/javascript; charset=utf-8");
  EXPECT_EQ(content_type_for("a.css"), "text/css; charset=utf-8");
  EXPECT_EQ(content_type_for("a.svg"), "image/svg+xml");
  EXPECT_EQ(content_type_for("a.wasm"), "application/wasm");
  EXPECT_EQ(content_type_for("a.json"), "application/json");
  EXPECT_EQ(content_type_for("noext"), "application/octet-stream");
  EXPECT_FALSE(canonical_web_root(base_ / "nowhere"));
  EXPECT_FALSE(canonical_web_root(base_ / "secret.txt"));
}

}  // namespace
}  // namespace duet::net
