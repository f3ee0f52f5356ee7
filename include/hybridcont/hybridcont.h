// Umbrella header: everything a user of the hybridcont library needs.
#ifndef HYBRIDCONT_HYBRIDCONT_H_
#define HYBRIDCONT_HYBRIDCONT_H_

#include "hybridcont/derivative_check.h"
#include "hybridcont/flow.h"
#include "hybridcont/model.h"
#include "hybridcont/models.h"
#include "hybridcont/shooting_layout.h"
#include "hybridcont/timebased_shooting.h"
#include "hybridcont/types.h"
#include "hybridcont/zero_problem.h"

#endif  // HYBRIDCONT_HYBRIDCONT_H_
