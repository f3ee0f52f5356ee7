// Test (monitor) functions along a branch: scalar functions g(u) that the continuation samples at every
// accepted point and whose zeros it detects and locates like SB and turning points, so that they land in
// Branch::special_points (special_point.h) with the same honesty (located or bracketed, precision,
// interval). The Floquet multipliers crossing +1 or −1 (floquet_test_functions.h) are one provider; a
// user may supply any other (BifurcationKit's events, COCO's monitor functions).
//
// Detection between consecutive branch points a, b (docs/design/continuation.md, "Test functions"):
//   - a sign change of g between a and b (or between the extra samples below) is located by the root
//     finder of the SB and turning points (Illinois on the curve, special_point.h);
//   - the step is sampled again on the curve between the SB and turning points located inside it: a step
//     across a fold and an SB point may hold a whole excursion of the multipliers (on the bouncing rod the
//     pair enters the unit circle at the fold, passes −1 and back, and leaves it at the SB point);
//   - two roots inside one step cancel in the signs: at every local minimum of |g| over the samples, g is
//     minimized on the curve over the two neighbouring intervals, and a value of the other sign brackets
//     both roots, each located;
//   - a zero that g touches without changing sign (a double zero: on the bouncing rod's symmetric orbits a
//     reciprocal pair of multipliers passes through −1 on the unit circle, and the PD test is a square
//     there) is the minimum of |g| refined on the curve (Brent) to location_tolerance; where that minimum
//     is at most 1e-10 of |g| at the samples around it, it is one located point whose message begins
//     "touching zero", its interval the bracket or the distance by which the bowl may miss zero;
//   - where g is undefined (NaN: e.g. a non-physical orbit) nothing is detected next to it; in the first
//     interval of a branch from a singular point a test that vanishes at that point (below
//     kStartNoise of its value at the next point) marks the parent's special point, not a new one.
//
//   class Height : public TestFunctions {   // zeros of u_1 − 0.5 along the unit circle
//     std::vector<SpecialPointType> types() const override { return {SpecialPointType::kUserTestFunction}; }
//     void Evaluate(const Vector& u, bool, Vector* g) override { *g = Vector::Constant(1, u(1) - 0.5); }
//     std::unique_ptr<TestFunctions> Clone() const override { return std::make_unique<Height>(); }
//   };
//   options.test_functions = std::make_shared<Height>();
//   Branch branch = TraceBranch(&circle, u0, options);   // two kUserTestFunction points at y = 0.5
#ifndef HYBRIDCONT_TEST_FUNCTION_H_
#define HYBRIDCONT_TEST_FUNCTION_H_

#include <memory>
#include <vector>

#include "hybridcont/special_point.h"
#include "hybridcont/types.h"
#include "hybridcont/zero_problem.h"

namespace hybridcont {

class TestFunctions {
 public:
  virtual ~TestFunctions() = default;
  // The special point each function marks, one entry per function (the order of Evaluate's values).
  virtual std::vector<SpecialPointType> types() const = 0;
  // g(u) of every function into *values (resized to types().size()), u in the continued problem's
  // unknowns. NaN where a function is undefined at u: no sign, so no special point next to it.
  // branch_point: u is an accepted branch point (a provider checks there what must hold along a whole step,
  // e.g. that the orbit is physical); otherwise u is a trial point of the root finder between two of them.
  virtual void Evaluate(const Vector& u, bool branch_point, Vector* values) = 0;
  // g_j(u) of function `function` alone at a trial point (Evaluate's branch_point false), for the root finder
  // that locates one of its zeros: a provider whose functions need different work (a multiplier needs the
  // map's Jacobian, an event's crossing speed its value alone, a phase's duration nothing but u) computes
  // only what that one needs. Equal to Evaluate(u, false, values)(function) up to the provider's own
  // precision (an integration without the sensitivities takes other steps). The default is exactly that.
  virtual double EvaluateOne(int function, const Vector& u) {
    Vector values;
    Evaluate(u, false, &values);
    return values(function);
  }
  // The continued problem as the corrector left it at an accepted branch point u: `problem` (the stepper's
  // own copy) last evaluated r and dr at `at`, the corrector's last iterate, at most
  // CorrectorOptions::max_jacobian_distance·(1 + ||u||) from u (corrector.h, evaluated_point()). A provider
  // whose values come from the same map may take them from that evaluation instead of integrating u again:
  // they are then those of a point within that distance, equal to u's to the map's precision, and it returns
  // true (the point records `at`, ContinuationPoint::evaluated_at). The default evaluates at u (Evaluate(u,
  // true, values)) and returns false. The stepper calls it instead of Evaluate at every branch point it
  // corrected; at others (a singular start, a mapped branch) it calls Evaluate.
  struct CorrectorEvaluation {
    ZeroProblem* problem = nullptr;
    Vector at;
  };
  virtual bool EvaluateAtBranchPoint(const Vector& u, const CorrectorEvaluation& evaluation, Vector* values) {
    (void)evaluation;
    Evaluate(u, true, values);
    return false;
  }
  // Called once for each zero of function `function` located at u: false drops it (a zero that marks no
  // special point of its type, e.g. a neutral saddle of a Neimark–Sacker test); *note is added to its
  // message. The default keeps every zero.
  virtual bool Keep(int function, const Vector& u, std::string* note) {
    (void)function, (void)u, (void)note;
    return true;
  }
  // Asked before a zero of function `function` is located between the curve points a and b (a sign change
  // or a dip of |g| there): false when Keep would drop every zero between them (a zero that marks nothing
  // where neither end is of a class next to which the special point can lie), so that the location's work
  // is not spent. The default is true.
  virtual bool MayKeepZeroBetween(int function, const Vector& a, const Vector& b) {
    (void)function, (void)a, (void)b;
    return true;
  }
  // At a branch point u of a branch mapped by a symmetry of the continued problem (exploration.h), the image
  // of the branch point `preimage` whose values were taken before: a provider may take what the symmetry
  // leaves invariant from what it learnt there. The default evaluates at u (Evaluate(u, true, values)).
  virtual void EvaluateAtImage(const Vector& u, const Vector& preimage, Vector* values) {
    (void)preimage;
    Evaluate(u, true, values);
  }
  // An independent copy for another stepper (another thread): its own scratch space.
  virtual std::unique_ptr<TestFunctions> Clone() const = 0;
  // A copy whose evaluation error is `factor` < 1 times this one's (ZeroProblem::Refined): estimates the
  // integration error of a located point (special_point.h, "Integration error"). nullptr: exact to
  // rounding.
  virtual std::unique_ptr<TestFunctions> Refined(double factor) const {
    (void)factor;
    return nullptr;
  }
  // The work of the copy of the continued problem (ZeroProblem::Clone) on which a stepper found the curve
  // points these functions needed (samples inside a step, the location of their zeros), handed over once,
  // when that stepper is done. It is the test functions' work and is never counted as the continued
  // problem's; a provider that reports its work adds it to its own counters (the default drops it).
  virtual void AddCurveWork(const ZeroProblem& copy) { (void)copy; }
};

}  // namespace hybridcont

#endif  // HYBRIDCONT_TEST_FUNCTION_H_
