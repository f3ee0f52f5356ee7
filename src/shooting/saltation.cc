#include "hybridcont/saltation.h"

#include <cmath>
#include <limits>

#include "hybridcont/internal/enum_names.h"

namespace hybridcont {

namespace {

constexpr internal::EnumName<SaltationStatus> kSaltationStatusNames[] = {
    {SaltationStatus::kSuccess, "success"},
    {SaltationStatus::kDegenerate, "degenerate (grazing: de f^- = 0)"},
};

}  // namespace

std::string ToString(SaltationStatus status) { return internal::EnumToString(kSaltationStatusNames, status); }

namespace {

// de f^- if the crossing is transversal enough, NaN otherwise.
double CrossingRate(const Vector& f_minus, const RowVector& de, double min_transversality) {
  const double rate = de.dot(f_minus);
  if (!std::isfinite(rate) || !(std::abs(rate) > min_transversality * de.norm() * f_minus.norm())) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  return rate;
}

}  // namespace

SaltationStatus Saltation(const Matrix& D, const Vector& f_minus, const Vector& f_plus, const RowVector& de,
                          Matrix* S, double min_transversality) {
  const double rate = CrossingRate(f_minus, de, min_transversality);
  if (std::isnan(rate)) return SaltationStatus::kDegenerate;
  *S = D;
  S->noalias() += ((f_plus - D * f_minus) / rate) * de;
  return SaltationStatus::kSuccess;
}

SaltationStatus LastSaltation(const Matrix& D, const Vector& f_minus, const RowVector& de, Matrix* S,
                              double min_transversality) {
  const double rate = CrossingRate(f_minus, de, min_transversality);
  if (std::isnan(rate)) return SaltationStatus::kDegenerate;
  *S = D;
  S->noalias() -= ((D * f_minus) / rate) * de;
  return SaltationStatus::kSuccess;
}

SaltationStatus SectionProjection(const Vector& f, const RowVector& da, Matrix* Pi, double min_transversality) {
  const double rate = CrossingRate(f, da, min_transversality);
  if (std::isnan(rate)) return SaltationStatus::kDegenerate;
  Pi->setIdentity(f.size(), f.size());
  Pi->noalias() -= (f / rate) * da;
  return SaltationStatus::kSuccess;
}

}  // namespace hybridcont
