#include "hybridcont/special_point.h"

#include <sstream>

namespace hybridcont {

std::string ToString(SpecialPointType type) {
  switch (type) {
    case SpecialPointType::kSimpleBifurcation: return "simple-bifurcation";
    case SpecialPointType::kTurningPoint: return "turning-point";
    case SpecialPointType::kSingularStart: return "singular-start";
  }
  return "unknown";
}

std::string ToString(LocationStatus status) {
  return status == LocationStatus::kLocated ? "located" : "bracketed";
}

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
