// render::svg_to_png: a PNG (signature, IHDR) of the size the SVG's width and height attributes
// give, for a run's picture and a hand-written document; clear errors for a bad SVG and an
// unwritable file.
#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>

#include "svg_test_support.hpp"
#include "temp_dir.hpp"
#include "vnsba/core/planner.hpp"
#include "vnsba/maps/map_io.hpp"
#include "vnsba/render/png.hpp"
#include "vnsba/render/run_picture.hpp"
#include "vnsba/render/svg.hpp"

namespace vnsba::test {
namespace {

// PNG's 8-byte signature (PNG specification, section 5.2).
const std::string kPngSignature("\x89PNG\r\n\x1a\n", 8);

struct PngSize {
  uint32_t width = 0;
  uint32_t height = 0;
};

// The first chunk after the signature is IHDR: length 13, "IHDR", width, height (big-endian).
PngSize ihdr_size(const std::string& png) {
  EXPECT_GE(png.size(), 24u);
  if (png.size() < 24) return {};
  EXPECT_EQ(png.substr(0, 8), kPngSignature);
  EXPECT_EQ(big_endian(png, 8), 13u);
  EXPECT_EQ(png.substr(12, 4), "IHDR");
  return {big_endian(png, 16), big_endian(png, 20)};
}

// The pixel size the SVG's root declares: its width and height attributes, rounded up.
PngSize declared_size(const std::string& svg) {
  tinyxml2::XMLDocument doc;
  EXPECT_EQ(doc.Parse(svg.c_str()), tinyxml2::XML_SUCCESS);
  const tinyxml2::XMLElement* root = doc.RootElement();
  if (root == nullptr) return {};
  return {static_cast<uint32_t>(std::ceil(root->DoubleAttribute("width"))),
          static_cast<uint32_t>(std::ceil(root->DoubleAttribute("height")))};
}

std::string run_svg() {
  auto grid = maps::load_movingai_map(VNSBA_FIXTURE_DIR "/maps/rooms_32.map");
  EXPECT_TRUE(grid) << grid.error().message;
  auto built = core::GridMap::build(*grid);
  EXPECT_TRUE(built);
  auto map = std::make_shared<const core::GridMap>(std::move(built).value());
  const core::PlanQuery query{{2, 2}, {29, 13}};
  core::PlannerSettings settings;
  settings.record_expansions = true;
  const core::PlanResult result =
      core::plan_once(map, query, core::make_options(core::PlannerKind::kVnsBaStar, settings));
  EXPECT_TRUE(result.status.is_ok()) << result.status.message;
  auto picture = std::make_shared<const render::MapPicture>(
      render::map_picture(*grid, core::GridBuildOptions{}.occupied_threshold, map.get()));
  return render::render_svg(render::picture_of(picture, query, result));
}

TEST(Png, RunPictureHasTheSvgsSize) {
  const std::string svg = run_svg();
  const auto png = render::svg_to_png(svg);
  ASSERT_TRUE(png) << png.error().message;
  const PngSize size = ihdr_size(*png);
  const PngSize declared = declared_size(svg);
  ASSERT_GT(declared.width, 0u);
  EXPECT_EQ(size.width, declared.width);
  EXPECT_EQ(size.height, declared.height);
}

TEST(Png, FractionalSizeRoundsUp) {
  const std::string svg =
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"40.5\" height=\"17\" "
      "viewBox=\"0 0 81 34\"><rect width=\"81\" height=\"34\" fill=\"red\"/></svg>";
  const auto png = render::svg_to_png(svg);
  ASSERT_TRUE(png) << png.error().message;
  const PngSize size = ihdr_size(*png);
  EXPECT_EQ(size.width, 41u);
  EXPECT_EQ(size.height, 17u);
}

TEST(Png, WritesTheFile) {
  const std::string path = (FreshTempDir("png") / "picture.png").string();
  const std::string svg = run_svg();
  ASSERT_TRUE(render::write_png_file(path, svg).is_ok());
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const PngSize size = ihdr_size(bytes);
  EXPECT_EQ(size.width, declared_size(svg).width);
  std::remove(path.c_str());
}

TEST(Png, BadSvgAndUnwritableFileAreClearErrors) {
  const auto bad = render::svg_to_png("<svg this is not xml");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("SVG"), std::string::npos) << bad.error().message;

  const auto huge = render::svg_to_png(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"100000\" height=\"100000\"/>");
  ASSERT_FALSE(huge);
  EXPECT_NE(huge.error().message.find("pixels"), std::string::npos) << huge.error().message;

  // A folder that does not exist, in an empty directory of its own: nothing can have made it.
  const std::string path =
      (FreshTempDir("png_unwritable") / "no_such_dir" / "picture.png").string();
  const core::Status written = render::write_png_file(path, run_svg());
  ASSERT_FALSE(written.is_ok());
  EXPECT_NE(written.message.find(path), std::string::npos) << written.message;
}

}  // namespace
}  // namespace vnsba::test
