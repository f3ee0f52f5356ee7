#include <stdexcept>

#include "hybridcont/models.h"
#include "hybridcont/setup_evaluation.h"

namespace hybridcont {
namespace {

struct Entry {
  const char* name;
  HybridModel (*make)();
};

const std::vector<Entry>& Registry() {
  static const std::vector<Entry> entries = {
      {"bouncing-ball", &MakeBouncingBall},
      {"rocking-block", &MakeRockingBlock},
      {"bouncing-rod", &MakeBouncingRod},
      {"slip", &MakeSlip},
      {"ball-chain", [] { return MakeBallChain(10); }},
  };
  return entries;
}

}  // namespace

std::vector<std::string> BuiltinModelNames() {
  std::vector<std::string> names;
  for (const Entry& e : Registry()) names.push_back(e.name);
  return names;
}

HybridModel MakeBuiltinModel(const std::string& name) {
  std::string known;
  for (const Entry& e : Registry()) {
    if (name == e.name) return e.make();
    known += (known.empty() ? "" : ", ") + std::string(e.name);
  }
  throw std::invalid_argument("unknown model '" + name + "' (built-in models: " + known + ")");
}

Vector BuiltinStartPoint(const HybridModel& model) { return StartPoint(model); }

}  // namespace hybridcont
