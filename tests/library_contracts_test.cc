// Contracts of the library toward its callers (a Python binding, a sweep worker, a user's program): an
// index out of range is the caller's error and an exception, not an abort; the default is one thread, so
// that many workers on one machine do not oversubscribe it; renumbering a diagram explored on its own
// (a period-doubled family, another word) moves branch and point ids, never the point index of a reflected
// loop.
#include <gtest/gtest.h>

#include <stdexcept>

#include "hybridcont/exploration.h"
#include "hybridcont/models.h"
#include "hybridcont/shooting_layout.h"
#include "study/engine/model_exploration.h"

namespace hybridcont {
namespace {

TEST(LibraryContracts, ASegmentIndexOutOfRangeIsAnException) {
  const HybridModel slip = MakeSlip();
  const ShootingLayout layout(slip);
  EXPECT_NO_THROW(layout.dim(layout.num_segments() - 1));
  EXPECT_THROW(layout.dim(layout.num_segments()), std::out_of_range);
  EXPECT_THROW(layout.time_index(-1), std::out_of_range);
  EXPECT_THROW(layout.state_offset(99), std::out_of_range);
  try {
    layout.block_row(7);
    FAIL() << "no exception";
  } catch (const std::out_of_range& e) {
    EXPECT_STREQ(e.what(), "ShootingLayout: segment 7 outside [0, 3)");
  }
}

TEST(LibraryContracts, AnExplorationUsesOneThreadUnlessTold) { EXPECT_EQ(ExplorationOptions{}.threads, 1); }

TEST(LibraryContracts, RenumberingKeepsTheReflectedLoopsPointIndex) {
  BifurcationDiagram d;
  Branch loop;
  loop.id = 2;
  loop.parent_special_point = 4;
  loop.reflected_from = 17;  // its points from index 17 on are the images of the earlier ones
  loop.image_of = -1;
  SpecialPoint sp;
  sp.id = 5;
  sp.branch_id = 2;
  loop.special_points.push_back(sp);
  d.branches.push_back(loop);
  d.special_points.push_back(sp);
  study::RenumberDiagram(/*branch_offset=*/10, /*point_offset=*/100, &d);
  const Branch& b = d.branches.front();
  EXPECT_EQ(b.id, 12);
  EXPECT_EQ(b.parent_special_point, 104);
  EXPECT_EQ(b.reflected_from, 17);
  EXPECT_EQ(b.image_of, -1);
  EXPECT_EQ(b.special_points.front().id, 105);
  EXPECT_EQ(b.special_points.front().branch_id, 12);
  EXPECT_EQ(d.special_points.front().id, 105);
}

}  // namespace
}  // namespace hybridcont
