// Branches obtained as images of merged branches under the problem's symmetries instead of being traced
// (docs/design/exploration.md, "Symmetries").
//
// A half-branch leaving p along v is the image of a merged branch starting at q along w when S q = p and
// S w ∥ v for a symmetry S (a sign involution u -> S u): that branch mapped point by point (u -> S u,
// τ -> S τ, special points likewise), checked by evaluations at its first and last mapped points. A
// symmetry failing the check is dropped for the rest of the run, with a warning.
//
//   SymmetricImages images(problem, options);
//   if (std::optional<Branch> image = images.Image(half, id, merged, evaluator, &warnings)) { ... }
#ifndef HYBRIDCONT_BIFURCATION_SYMMETRIC_IMAGES_H_
#define HYBRIDCONT_BIFURCATION_SYMMETRIC_IMAGES_H_

#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "bifurcation/half_branch.h"
#include "continuation/linear_stop.h"
#include "hybridcont/continuation.h"
#include "hybridcont/exploration.h"
#include "hybridcont/types.h"
#include "hybridcont/zero_problem.h"

namespace hybridcont::internal {

class SymmetricImages {
 public:
  SymmetricImages() = default;
  // The problem's symmetries that map every stop of options.continuation onto itself (none when
  // use_symmetries is off or a stop_predicate is set, which cannot be checked). `options` must outlive this.
  SymmetricImages(ZeroProblem* problem, const ExplorationOptions& options);

  // The symmetries in use; one that failed its check is no longer among them.
  const std::vector<Symmetry>& symmetries() const { return symmetries_; }

  // Whether a symmetry in use maps the ray (q, w) onto the ray (p, v).
  bool MapsAnyRay(const Vector& q, const Vector& w, const Vector& p, const Vector& v) const;

  // A branch whose own end did not depend on the order of tracing, with a point past its start.
  static bool Mappable(const Branch& source);

  // `half` as the image of a merged branch, as branch `id`, checked on `evaluator`; nothing when no merged
  // branch maps onto it or the check fails (then it is traced). The serial trace's known-branch check on
  // its first points is repeated against `merged`.
  std::optional<Branch> Image(const HalfBranch& half, int id, const std::deque<Branch>& merged,
                              ZeroProblem* evaluator, std::vector<std::string>* warnings);

  // The progress reports the stepper would have made for the image's points.
  void ReportImage(const Branch& image, std::vector<ProgressInfo>* reports) const;

 private:
  bool MapsStopsOntoThemselves(const Symmetry& g, const ZeroProblem& problem) const;
  bool MapsRay(const Symmetry& g, const Vector& q, const Vector& w, const Vector& p, const Vector& v) const;
  std::optional<Branch> MapBranch(const Branch& source, const Symmetry& g, int id, const std::deque<Branch>& merged,
                                  ZeroProblem* evaluator, std::vector<std::string>* warnings) const;
  std::optional<double> CheckImage(const Branch& source, const Branch& image, const Symmetry& g,
                                   ZeroProblem* evaluator, std::vector<std::string>* warnings) const;
  void EndAtKnownBranch(const std::deque<Branch>& merged, Branch* image) const;
  std::string ImageStopMessage(const std::string& message, const Symmetry& g) const;

  const ExplorationOptions* options_ = nullptr;
  std::vector<Symmetry> symmetries_;
  std::vector<LinearStop> stops_;      // ContinuationOptions' linear stops, for image messages
  std::vector<int> progress_indices_;  // ContinuationOptions::progress_components
};

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_BIFURCATION_SYMMETRIC_IMAGES_H_
