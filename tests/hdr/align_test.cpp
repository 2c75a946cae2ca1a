#include "hdr/align.h"

#include <gtest/gtest.h>

#include "tools/common/error.h"

namespace igi::hdr {
namespace {

Image Memorial(int i) {
  return ReadImage(std::string(IGI_SHARED_DATA_DIR) + "/real/memorial/memorial00" +
                   std::to_string(i) + ".png");
}

TEST(Align, ShiftImageMovesContentAndRepeatsBorders) {
  Image image(3, 2, 1);
  image.pixels = {1, 2, 3, 4, 5, 6};
  const Image moved = ShiftImage(image, {1, 0});
  EXPECT_EQ(moved.pixels, (std::vector<float>{1, 1, 2, 4, 4, 5}));
  const Image up = ShiftImage(image, {0, -1});
  EXPECT_EQ(up.pixels, (std::vector<float>{4, 5, 6, 4, 5, 6}));
}

// Memorial exposures one stop apart (their levels differ everywhere, which is what threshold
// bitmaps are for): the darker frames are moved by known shifts and found again, exactly,
// through the chain 68 -> 69 -> 70. (Pairs two or more stops apart are not reliable on this
// dark bracket: the shared well-exposed pixels are few; hence the chaining.)
TEST(Align, RecoversKnownShiftsAlongABracket) {
  const std::vector<PixelShift> applied = {{0, 0}, {7, -4}, {-12, 9}};
  std::vector<Image> images;
  for (int k = 0; k < 3; ++k) images.push_back(ShiftImage(Memorial(68 + k), applied[size_t(k)]));
  const std::vector<PixelShift> shifts = ComputeMtbShifts(images, 0);
  ASSERT_EQ(shifts.size(), 3u);
  for (size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(shifts[k].dx, -applied[k].dx) << "image " << k;
    EXPECT_EQ(shifts[k].dy, -applied[k].dy) << "image " << k;
  }
}

TEST(Align, OptionsAreValidated) {
  AlignOptions options;
  options.max_bits = 0;
  EXPECT_THROW(options.Validate(), InputError);
}

}  // namespace
}  // namespace igi::hdr
