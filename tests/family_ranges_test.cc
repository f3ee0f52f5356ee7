// Ranges of physical and stable orbits on a branch (family_ranges.h): each end from the special point located
// between the two points where the class changes, at a boundary point itself, else said to be not located.
#include <gtest/gtest.h>

#include <cmath>

#include "hybridcont/family_ranges.h"

namespace hybridcont {
namespace {

// A branch of 8 points with u = (s, 10 s) at s = 0, 1, ..., 7: the coordinate 1 is 10 s.
Branch EightPoints() {
  Branch b;
  b.id = 3;
  b.termination = TerminationReason::kBoundReached;
  for (int i = 0; i < 8; ++i) {
    ContinuationPoint p;
    p.u = Vector(2);
    p.u << i, 10.0 * i;
    b.points.push_back(p);
  }
  return b;
}

SpecialPoint At(SpecialPointType type, int id, int after, double s, double width) {
  SpecialPoint sp;
  sp.type = type;
  sp.id = id;
  sp.index = after;
  sp.status = LocationStatus::kLocated;
  sp.u = Vector(2);
  sp.u << s, 10 * s;
  sp.interval_width = Vector(2);
  sp.interval_width << width, 10 * width;
  return sp;
}

TEST(FamilyRanges, EndsAreTheLocatedSpecialPointsOrSaidToBeNotLocated) {
  Branch b = EightPoints();
  // Physical on points 1..5, stable on 3..5; a GR between 5 and 6, a PD between 2 and 3; point 0 is not
  // physical and not on the boundary, and nothing is located between 0 and 1.
  b.special_points = {At(SpecialPointType::kPeriodDoubling, 7, 2, 2.25, 1e-10),
                      At(SpecialPointType::kGrazing, 9, 5, 5.5, 2e-11)};
  const std::vector<bool> physical = {false, true, true, true, true, true, false, false};
  const std::vector<bool> stable = {false, false, false, true, true, true, false, false};
  const std::vector<bool> boundary(8, false);
  const BranchRanges r = RangesOnBranch(b, physical, stable, boundary, 1);
  ASSERT_EQ(r.physical.size(), 1u);
  EXPECT_FALSE(r.physical[0].from.located);
  EXPECT_DOUBLE_EQ(r.physical[0].from.value, 5.0);  // midway between points 0 and 1, to within half of it
  EXPECT_DOUBLE_EQ(r.physical[0].from.precision, 5.0);
  EXPECT_EQ(r.physical[0].from.how, "between points 0 and 1, not located");
  EXPECT_TRUE(r.physical[0].to.located);
  EXPECT_DOUBLE_EQ(r.physical[0].to.value, 55.0);
  EXPECT_DOUBLE_EQ(r.physical[0].to.precision, 2e-10);
  EXPECT_EQ(r.physical[0].to.special_point, 9);
  EXPECT_EQ(r.physical[0].to.how, "GR #9, located to 2.0e-10");
  ASSERT_EQ(r.stable.size(), 1u);
  EXPECT_DOUBLE_EQ(r.stable[0].from.value, 22.5);
  EXPECT_EQ(r.stable[0].from.special_point, 7);
  EXPECT_EQ(r.stable[0].to.special_point, 9);  // the family stops being physical: its stability ends there too
}

TEST(FamilyRanges, AStretchEndsAtABoundaryPointAndABranchPointAloneIsNoStableStretch) {
  Branch b = EightPoints();
  b.parent_special_point = 4;
  // Point 0: the SB point the branch leaves (neutral there), then unstable; physical to point 6, and point 7
  // has a phase of zero duration.
  const std::vector<bool> physical = {true, true, true, true, true, true, true, false};
  const std::vector<bool> stable = {true, false, false, false, false, false, false, false};
  std::vector<bool> boundary(8, false);
  boundary[7] = true;
  const BranchRanges r = RangesOnBranch(b, physical, stable, boundary, 0);
  ASSERT_EQ(r.physical.size(), 1u);
  EXPECT_EQ(r.physical[0].from.how, "start of the branch, at special point #4");
  EXPECT_EQ(r.physical[0].from.special_point, 4);
  EXPECT_TRUE(r.physical[0].to.located);
  EXPECT_DOUBLE_EQ(r.physical[0].to.value, 7.0);
  EXPECT_EQ(r.physical[0].to.how, "point 7, on the boundary");
  EXPECT_TRUE(r.stable.empty());
}

// A family that starts at rest (point 0: zero duration, on the boundary) and is stable from its first orbit
// on: physical and stable both from the boundary point, exactly.
TEST(FamilyRanges, AStableStretchStartsAtABoundaryPointToo) {
  const Branch b = EightPoints();
  const std::vector<bool> physical = {false, true, true, true, true, true, true, true};
  const std::vector<bool> stable = {false, true, true, true, true, true, true, true};
  std::vector<bool> boundary(8, false);
  boundary[0] = true;
  const BranchRanges r = RangesOnBranch(b, physical, stable, boundary, 0);
  ASSERT_EQ(r.physical.size(), 1u);
  ASSERT_EQ(r.stable.size(), 1u);
  for (const Range* range : {&r.physical[0], &r.stable[0]}) {
    EXPECT_TRUE(range->from.located);
    EXPECT_EQ(range->from.how, "point 0, on the boundary");
    EXPECT_DOUBLE_EQ(range->from.value, 0.0);
  }
}

// A branch that leaves a special point, physical there only (its next point violates a constraint, nothing
// located between): the family's one physical orbit is that point, and the stretch ends where it starts.
TEST(FamilyRanges, APhysicalStartPointAloneIsAStretchOfOnePoint) {
  Branch b = EightPoints();
  b.parent_special_point = 2;
  const std::vector<bool> physical = {true, false, false, false, false, false, false, false};
  const std::vector<bool> stable(8, false);
  const std::vector<bool> boundary(8, false);
  const BranchRanges r = RangesOnBranch(b, physical, stable, boundary, 0);
  ASSERT_EQ(r.physical.size(), 1u);
  EXPECT_EQ(r.physical[0].to.how, "start of the branch, at special point #2");
  EXPECT_EQ(r.physical[0].to.special_point, 2);
  EXPECT_DOUBLE_EQ(r.physical[0].to.value, r.physical[0].from.value);
}

// Orbits the integration does not resolve (a family whose period grows without bound): they belong to no
// stretch, and the stretches before them end at their own last point, exactly, saying so.
TEST(FamilyRanges, AStretchEndsAtTheLastOrbitTheIntegrationResolves) {
  const Branch b = EightPoints();
  const std::vector<bool> physical(8, true), stable(8, true), boundary(8, false);
  const std::vector<bool> unresolved = {false, false, false, false, false, true, true, true};
  const BranchRanges r = RangesOnBranch(b, physical, stable, boundary, 0, unresolved);
  ASSERT_EQ(r.physical.size(), 1u);
  ASSERT_EQ(r.stable.size(), 1u);
  for (const Range* range : {&r.physical[0], &r.stable[0]}) {
    EXPECT_EQ(range->last_point, 4);
    EXPECT_TRUE(range->to.located);
    EXPECT_DOUBLE_EQ(range->to.value, 4.0);
    EXPECT_EQ(range->to.how, "point 4, the last orbit the integration resolves");
  }
}

// A physical point whose multipliers cannot tell its stability: the stable stretch before it ends at the last
// point whose stability is known, saying so; the physical stretch goes on through it.
TEST(FamilyRanges, AStableStretchEndsWhereTheMultipliersStopTellingItsStability) {
  const Branch b = EightPoints();
  const std::vector<bool> physical(8, true), stable = {true, true, true, false, false, false, false, false};
  const std::vector<bool> boundary(8, false), unresolved;
  const std::vector<bool> undetermined = {false, false, false, true, false, false, false, false};
  const BranchRanges r = RangesOnBranch(b, physical, stable, boundary, 0, unresolved, undetermined);
  ASSERT_EQ(r.physical.size(), 1u);
  EXPECT_EQ(r.physical[0].last_point, 7);
  ASSERT_EQ(r.stable.size(), 1u);
  EXPECT_EQ(r.stable[0].last_point, 2);
  EXPECT_TRUE(r.stable[0].to.located);
  EXPECT_EQ(r.stable[0].to.how, "point 2, the last orbit whose multipliers tell its stability");
}

}  // namespace
}  // namespace hybridcont
