// Observables as test functions of the continuation (test_function.h): a monitored observable reaching a
// value (kObservableValue, AUTO's UZ points: `--monitor speed=1`), and each admissibility constraint of the
// model reaching 0 (kConstraintBoundary), located on the branch like any special point.
//
// A constraint's test function is its value: for a minimum its interior minimum (observable.h), NaN where
// the minimum lies at an end of its segments: a foot clearance that is 0 where the phase starts and ends has no sign there, and its
// boundary is where an interior dip touches 0. It is NaN too where some phase duration is <= 0 (a
// reversed-time or degenerate orbit, which no constraint makes physical or not).
//
// u is a point of the time-based map with `free` (shooting_layout.h): observables that joined the unknowns
// are read from u, the others evaluated at u's parameter values.
//
//   ObservableTestFunctions tests(model, IntegratorOptions{}, {}, {{"speed", 1.0}});
//   options.test_functions = std::make_shared<ObservableTestFunctions>(tests);
#ifndef HYBRIDCONT_OBSERVABLE_TEST_FUNCTIONS_H_
#define HYBRIDCONT_OBSERVABLE_TEST_FUNCTIONS_H_

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "hybridcont/orbit_observables.h"
#include "hybridcont/test_function.h"

namespace hybridcont {

class ObservableTestFunctions : public TestFunctions {
 public:
  // Keeps a reference to model (it must outlive this object and its copies). Throws std::invalid_argument
  // naming a monitored observable the model does not have.
  ObservableTestFunctions(const HybridModel& model, const IntegratorOptions& integrator, FreeParameters free,
                          std::vector<std::pair<std::string, double>> monitors);
  // Monitors first (in the order given), then the model's constraints.
  std::vector<SpecialPointType> types() const override;
  void Evaluate(const Vector& u, bool branch_point, Vector* values) override;
  bool Keep(int function, const Vector& u, std::string* note) override;
  std::unique_ptr<TestFunctions> Clone() const override;
  std::unique_ptr<TestFunctions> Refined(double factor) const override;
  // Number of functions (monitors and constraints); 0: nothing to test.
  int size() const { return static_cast<int>(functions_.size()); }

 private:
  void SetParameters(const Vector& u);

  const HybridModel* model_;
  IntegratorOptions integrator_;
  FreeParameters free_;
  std::vector<std::pair<std::string, double>> monitors_;
  ShootingLayout layout_;
  std::unique_ptr<HybridModel> point_model_;  // with free parameters: the model at u's values
  std::unique_ptr<ObservableEvaluator> evaluator_;
  struct Function {
    int observable;  // index into model.observables()
    double value;    // the monitored value (0 for a constraint)
    bool constraint;
    int unknown;     // its index in u where it joined the unknowns (a monitor), else -1: evaluated
  };
  std::vector<Function> functions_;
};

}  // namespace hybridcont

#endif  // HYBRIDCONT_OBSERVABLE_TEST_FUNCTIONS_H_
