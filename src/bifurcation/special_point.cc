#include "hybridcont/special_point.h"

#include <sstream>

#include "hybridcont/internal/enum_names.h"

namespace hybridcont {

namespace {

constexpr internal::EnumName<SpecialPointType> kSpecialPointTypeNames[] = {
    {SpecialPointType::kSimpleBifurcation, "simple-bifurcation"},
    {SpecialPointType::kTurningPoint, "turning-point"},
    {SpecialPointType::kSingularStart, "singular-start"},
    {SpecialPointType::kFloquetBranchPoint, "floquet-branch-point"},
    {SpecialPointType::kPeriodDoubling, "period-doubling"},
    {SpecialPointType::kGrazing, "grazing"},
    {SpecialPointType::kNeimarkSacker, "neimark-sacker"},
    {SpecialPointType::kObservableValue, "observable-value"},
    {SpecialPointType::kConstraintBoundary, "constraint-boundary"},
    {SpecialPointType::kKreinCollision, "krein-collision"},
    {SpecialPointType::kUserTestFunction, "test-function-zero"},
    {SpecialPointType::kZeroDuration, "zero-duration"},
    {SpecialPointType::kExtremum, "extremum"},
};

constexpr internal::EnumName<LocationStatus> kLocationStatusNames[] = {
    {LocationStatus::kLocated, "located"},
    {LocationStatus::kBracketed, "bracketed"},
};

}  // namespace

std::string ToString(SpecialPointType type) { return internal::EnumToString(kSpecialPointTypeNames, type); }

std::string Code(SpecialPointType type) {
  switch (type) {
    case SpecialPointType::kSimpleBifurcation: return "SB";
    case SpecialPointType::kTurningPoint: return "TP";
    case SpecialPointType::kSingularStart: return "start";
    case SpecialPointType::kFloquetBranchPoint: return "BP";
    case SpecialPointType::kPeriodDoubling: return "PD";
    case SpecialPointType::kUserTestFunction: return "test";
    case SpecialPointType::kGrazing: return "GR";
    case SpecialPointType::kNeimarkSacker: return "NS";
    case SpecialPointType::kObservableValue: return "UZ";
    case SpecialPointType::kConstraintBoundary: return "CB";
    case SpecialPointType::kKreinCollision: return "KC";
    case SpecialPointType::kZeroDuration: return "ZD";
    case SpecialPointType::kExtremum: return "EX";
  }
  return "?";
}

bool FromCode(const std::string& code, SpecialPointType* type) {
  for (int t = 0; t <= static_cast<int>(kLastSpecialPointType); ++t) {
    if (Code(static_cast<SpecialPointType>(t)) == code) {
      *type = static_cast<SpecialPointType>(t);
      return true;
    }
  }
  return false;
}

std::string ToString(LocationStatus status) { return internal::EnumToString(kLocationStatusNames, status); }

std::string SpecialPoint::BriefReport(const std::vector<std::string>& names) const {
  std::ostringstream out;
  out.precision(12);
  out << "#" << id << " " << ToString(type);
  if (!component.empty()) out << " in " << component;
  out << " (" << ToString(status) << ") on branch " << branch_id << " after point " << index << ", s = " << arclength
      << ", u = (";
  for (Eigen::Index i = 0; i < u.size(); ++i) {
    if (i > 0) out << ", ";
    if (i < static_cast<Eigen::Index>(names.size())) out << names[i] << "=";
    out << u(i);
  }
  out.precision(3);
  out << "), precision " << precision() << " in arclength, |r| = " << residual_norm;
  if (duplicate_of >= 0) out << ", same as #" << duplicate_of;
  if (!message.empty()) out << " [" << message << "]";
  return out.str();
}

}  // namespace hybridcont
