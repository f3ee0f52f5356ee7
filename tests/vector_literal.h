// Vec({a, b, c}): a hybridcont::Vector from a brace list, for short states in tests.
#ifndef HYBRIDCONT_TESTS_VECTOR_LITERAL_H_
#define HYBRIDCONT_TESTS_VECTOR_LITERAL_H_

#include <initializer_list>

#include "hybridcont/types.h"

namespace hybridcont {

inline Vector Vec(std::initializer_list<double> values) {
  Vector x(static_cast<int>(values.size()));
  int i = 0;
  for (double v : values) x(i++) = v;
  return x;
}

}  // namespace hybridcont

#endif  // HYBRIDCONT_TESTS_VECTOR_LITERAL_H_
