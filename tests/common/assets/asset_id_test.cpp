// Asset ids: the SHA-256 of the canonical mesh file, and what counts as an id.
#include "common/assets/asset_id.h"

#include <gtest/gtest.h>

#include <string>

namespace skyfarm::assets {
namespace {

TEST(AssetId, Sha256OfKnownVectors) {
  // FIPS 180-2 test vectors.
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

TEST(AssetId, IdOfBytesIsAnId) {
  const std::string id = asset_id_of("abc");
  EXPECT_EQ(id, "sha256:ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_TRUE(is_asset_id(id));
  EXPECT_EQ(asset_hex(id), sha256_hex("abc"));
}

TEST(AssetId, RejectsWhatIsNotAnId) {
  const std::string hex(64, 'a');
  EXPECT_TRUE(is_asset_id("sha256:" + hex));
  EXPECT_FALSE(is_asset_id(hex)) << "no prefix";
  EXPECT_FALSE(is_asset_id("sha256:" + std::string(63, 'a'))) << "short";
  EXPECT_FALSE(is_asset_id("sha256:" + std::string(65, 'a'))) << "long";
  EXPECT_FALSE(is_asset_id("sha256:" + std::string(64, 'A'))) << "uppercase";
  EXPECT_FALSE(is_asset_id("sha512:" + hex));
  EXPECT_FALSE(is_asset_id("cube.obj"));
  EXPECT_FALSE(is_asset_id(""));
}

}  // namespace
}  // namespace skyfarm::assets
