// The built-in models of the paper (§4), registered by name. Each declares in its own source file its
// equations, parameters with their ranges, and its set-up (model_setup.h): start point, default run,
// family names, quantities, figures and drawing.
//
//   for (const std::string& name : BuiltinModelNames()) { ... }
//   HybridModel slip = MakeBuiltinModel("slip");     // k = 40, w2 = 5, m = l0 = g = 1
//   slip.SetParameter("k", 20.0);
//   Vector u0 = BuiltinStartPoint(slip);             // the T0 = 2 pi sqrt(m/k) oscillation at H = 1
//
// Normalized units m = l0 = g = 1 throughout; every parameter can be overridden at run time within its
// range.
#ifndef HYBRIDCONT_MODELS_H_
#define HYBRIDCONT_MODELS_H_

#include <string>
#include <vector>

#include "hybridcont/model.h"

namespace hybridcont {

// "bouncing-ball", "rocking-block", "bouncing-rod", "slip", plus the scalable test model "ball-chain".
std::vector<std::string> BuiltinModelNames();

// Builds the named model with its default parameters; throws std::invalid_argument listing the known
// names if there is none of that name.
HybridModel MakeBuiltinModel(const std::string& name);

// The model's start point at its current parameters: StartPoint (setup_evaluation.h), which evaluates
// setup().start. For the paper's models the equilibrium u0 = 0 (ball, block, rod) or the SLIP's harmonic
// oscillation with zero flight time at H = m g l0, singular points of r (bifurcation points) as in the
// paper; for the ball chain its closed-form orbit at H = 0.5.
Vector BuiltinStartPoint(const HybridModel& model);

// Individual factories (one source file each under src/models/).
HybridModel MakeBouncingBall();
HybridModel MakeRockingBlock();
HybridModel MakeBouncingRod();
HybridModel MakeSlip();

// The scalable test model "ball-chain": a ball bouncing num_phases times per period, one phase per bounce
// (the registry builds it with 10 phases). BallChainOrbit is its closed-form orbit at level H (period
// 2 num_phases sqrt(2H/g) for m = 1).
HybridModel MakeBallChain(int num_phases);
Vector BallChainOrbit(const HybridModel& chain, double H);

}  // namespace hybridcont

#endif  // HYBRIDCONT_MODELS_H_
