// Umbrella header: everything a user of the core hybridcont library needs (model files: model_file.h,
// in the hybridcont::modelfile target).
#ifndef HYBRIDCONT_HYBRIDCONT_H_
#define HYBRIDCONT_HYBRIDCONT_H_

#include "hybridcont/branch_switching.h"
#include "hybridcont/classification.h"
#include "hybridcont/continuation.h"
#include "hybridcont/corrector.h"
#include "hybridcont/derivative_check.h"
#include "hybridcont/event_flow.h"
#include "hybridcont/exploration.h"
#include "hybridcont/floquet.h"
#include "hybridcont/floquet_test_functions.h"
#include "hybridcont/flow.h"
#include "hybridcont/model.h"
#include "hybridcont/model_builder.h"
#include "hybridcont/model_setup.h"
#include "hybridcont/models.h"
#include "hybridcont/orbit_trace.h"
#include "hybridcont/period_doubling.h"
#include "hybridcont/poincare_map.h"
#include "hybridcont/replay.h"
#include "hybridcont/saltation.h"
#include "hybridcont/scaled_problem.h"
#include "hybridcont/setup_evaluation.h"
#include "hybridcont/shooting_layout.h"
#include "hybridcont/shooting_problem.h"
#include "hybridcont/special_point.h"
#include "hybridcont/special_point_curve.h"
#include "hybridcont/statebased_shooting.h"
#include "hybridcont/test_function.h"
#include "hybridcont/test_function_root.h"
#include "hybridcont/timebased_shooting.h"
#include "hybridcont/types.h"
#include "hybridcont/zero_problem.h"

#endif  // HYBRIDCONT_HYBRIDCONT_H_
