// The invariant channel: checks of what the library assumes of itself (indices in range, sizes that
// agree, states a caller has established), in the spirit of Drake's DRAKE_DEMAND.
//
// hybridcont has three error channels, each for one kind of failure:
//   - a programming error, a broken invariant: HYBRIDCONT_DEMAND(condition). Always armed (also in
//     Release builds, where numerical code runs): it prints the condition, file, line and function to
//     stderr and aborts. Its cost is one predictable branch; it is never used for anything a user's
//     input can cause.
//   - bad input from a user (a model file, a CLI option, an options struct, a Python call): an exception
//     (std::invalid_argument) whose message names the field, the value and, for files, the line.
//   - a numerical outcome (Newton did not converge, an event was missed, a step failed): a status in the
//     result (ContinuationStatus, CorrectorStatus, ...), with the work done so far kept.
#ifndef HYBRIDCONT_INVARIANT_H_
#define HYBRIDCONT_INVARIANT_H_

namespace hybridcont::internal {

// Reports a violated invariant and aborts; called only by the macros below.
[[noreturn]] void InvariantViolated(const char* condition, const char* file, int line, const char* function);

}  // namespace hybridcont::internal

// Aborts with a message naming `condition` when it is false.
#define HYBRIDCONT_DEMAND(condition)                                                              \
  do {                                                                                            \
    if (!(condition)) [[unlikely]]                                                                \
      ::hybridcont::internal::InvariantViolated(#condition, __FILE__, __LINE__, __func__);        \
  } while (false)

// Marks a point the control flow cannot reach (e.g. after a switch over every enumerator).
#define HYBRIDCONT_UNREACHABLE() \
  ::hybridcont::internal::InvariantViolated("unreachable code reached", __FILE__, __LINE__, __func__)

#endif  // HYBRIDCONT_INVARIANT_H_
