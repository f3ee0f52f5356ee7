// How far a declared start is from a periodic orbit, said in the model's own names.
//
// A start (model_setup.h, StartSpec) gives some unknowns of the time-based layout (shooting_layout.h) by
// name; the others are 0. A singular start must be an exact zero of r (the exploration analyses the kernel
// of dr there); a guess must be close enough for Newton. When it is not, the user needs to know which part
// of the cycle does not close, not a rank or a singular matrix:
//
//   StartResidual check = ExplainStartResidual(slip, slip.setup().start, IntegratorOptions{});
//   if (check.max_residual > 1e-8) std::cerr << check.Explain(1e-8);
//   // segment 2 (phase 'flight', t2 = 0.3): at its end (after the reset into segment 3) x3_l is off by 0.25,
//   //   x3_dl by 1.1; its event is 0.4 (0 on an orbit)
//   // unset (0): x3_alpha, x3_dalpha
//
// The rows of r are read block by block (shooting_layout.h): block i compares the end of segment i, after
// its reset, with the next segment's declared start state (the last block: the return to x̄_1) and holds
// segment i's event (the last block: the anchor); then the first integrals, H(x̄_1) − H̄.
#ifndef HYBRIDCONT_START_CHECK_H_
#define HYBRIDCONT_START_CHECK_H_

#include <string>
#include <vector>

#include "hybridcont/flow.h"
#include "hybridcont/model.h"
#include "hybridcont/model_setup.h"

namespace hybridcont {

struct StartResidual {
  Vector u;                          // the start in the time-based layout (StartPoint)
  bool evaluated = false;            // false: the map could not be evaluated at u (message says why)
  std::string message;
  double max_residual = 0;           // max-norm of r at u (infinity when not evaluated)
  Vector r;                          // r at u (empty when not evaluated)
  std::vector<std::string> unset;    // unknowns of the layout the start does not give (they are 0)

  // One line per block of r with an entry above `tolerance` (its largest entries by name), then the unset
  // unknowns; "" when every entry is within tolerance.
  std::string Explain(double tolerance) const;

 private:
  friend StartResidual ExplainStartResidual(const HybridModel&, const StartSpec&, const IntegratorOptions&,
                                            const Vector*);
  std::vector<std::string> block_lines_;  // per block: its description
  std::vector<std::vector<std::pair<std::string, double>>> block_entries_;  // per block: named entries
};

// r at the start, block by block (see the header comment); at `at` instead of StartPoint(start) when given
// (a start whose states a simulation filled in). Throws ModelInputError for a start value that does not
// evaluate or names no unknown (StartPoint).
StartResidual ExplainStartResidual(const HybridModel& model, const StartSpec& start,
                                   const IntegratorOptions& integrator, const Vector* at = nullptr);

// The tolerance below which a singular start counts as an exact zero of r: rounding of the start's
// expressions and of one evaluation, relative to the size of u.
double SingularStartTolerance(const Vector& u);

}  // namespace hybridcont

#endif  // HYBRIDCONT_START_CHECK_H_
