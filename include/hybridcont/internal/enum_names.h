// One table per enum gives both directions of its string form (configuration is data: conventions §14).
// Used by the library's sources to implement the public `ToString(E)` / `FromString(text, E*)`
// pairs; not used directly by library users.
//
//   constexpr internal::EnumName<PredictorType> kPredictorNames[] = {
//       {PredictorType::kTangent, "tangent"}, {PredictorType::kSecant, "secant"}};
//   std::string ToString(PredictorType t) { return internal::EnumToString(kPredictorNames, t); }
//   bool FromString(const std::string& s, PredictorType* t) { return internal::EnumFromString(kPredictorNames, s, t); }
//
// Contract: every enumerator has exactly one row. A value without a row is a programming error (an
// enumerator added without its name) and trips the invariant check; an unknown text is bad input and
// returns false, leaving *value unchanged.
#ifndef HYBRIDCONT_INTERNAL_ENUM_NAMES_H_
#define HYBRIDCONT_INTERNAL_ENUM_NAMES_H_

#include <cstddef>
#include <string>
#include <string_view>

#include "hybridcont/invariant.h"

namespace hybridcont::internal {

template <class E>
struct EnumName {
  E value;
  std::string_view name;
};

template <class E, std::size_t N>
std::string EnumToString(const EnumName<E> (&table)[N], E value) {
  for (const EnumName<E>& row : table) {
    if (row.value == value) return std::string(row.name);
  }
  HYBRIDCONT_UNREACHABLE();
}

template <class E, std::size_t N>
bool EnumFromString(const EnumName<E> (&table)[N], std::string_view text, E* value) {
  HYBRIDCONT_DEMAND(value != nullptr);
  for (const EnumName<E>& row : table) {
    if (row.name == text) {
      *value = row.value;
      return true;
    }
  }
  return false;
}

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_INTERNAL_ENUM_NAMES_H_
