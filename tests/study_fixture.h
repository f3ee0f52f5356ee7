// The one fixture of the tests that need a model's diagram: its study (study.h) on one thread, without a
// folder. Tests of the engine's own options (threads, steps, symmetries, the test functions' work) build the
// exploration themselves (study/model_exploration.h); every other test explores through this.
//
//   const StudyResult study = StudyOf(model);                    // typed families, analysis, special points
//   const BifurcationDiagram& d = *study.diagram;                 // the engine's diagram (tangents, widths)
#ifndef HYBRIDCONT_TESTS_STUDY_FIXTURE_H_
#define HYBRIDCONT_TESTS_STUDY_FIXTURE_H_

#include "hybridcont/exploration.h"
#include "hybridcont/study.h"

namespace hybridcont {

// The study of `model` with `options` (model and folder not read: none is written), on one thread: the
// diagram is the same at any thread count, and one core keeps the test cheap.
inline StudyResult StudyOf(const HybridModel& model, StudyOptions options = {}) {
  options.threads = 1;
  options.out_dir.clear();
  return RunStudy(model, options);
}

// Its integrator tolerances (rtol = atol).
inline StudyOptions WithTolerance(double tolerance) {
  StudyOptions options;
  options.rtol = tolerance;
  options.atol = tolerance;
  return options;
}

}  // namespace hybridcont

#endif  // HYBRIDCONT_TESTS_STUDY_FIXTURE_H_
