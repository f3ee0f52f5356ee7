#include "hybridcont/floquet.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include "hybridcont/saltation.h"

#include "hybridcont/internal/enum_names.h"
#include "hybridcont/internal/options_check.h"

namespace hybridcont {

namespace {

constexpr internal::EnumName<FloquetStatus> kFloquetStatusNames[] = {
    {FloquetStatus::kSuccess, "success"},
    {FloquetStatus::kEvaluationFailed, "evaluation failed"},
    {FloquetStatus::kSaltationUndefined, "saltation matrix undefined"},
    {FloquetStatus::kDegenerateOrbit, "degenerate orbit"},
    {FloquetStatus::kEigenFailed, "eigenvalue computation failed"},
};

}  // namespace

std::string FloquetOptions::Validate() const {
  return internal::OptionsCheck("FloquetOptions")
      .Positive("unit_tolerance", unit_tolerance)
      .Positive("circle_tolerance", circle_tolerance)
      .Positive("min_transversality", min_transversality)
      .Positive("branch_point_radius", branch_point_radius)
      .Positive("branch_point_product", branch_point_product)
      .message();
}

std::string ToString(FloquetStatus status) { return internal::EnumToString(kFloquetStatusNames, status); }

std::string FloquetResult::BriefReport() const {
  std::ostringstream os;
  os << ToString(status);
  if (!ok()) return os.str() + " (" + message + ")";
  os << ": " << (normal ? "normal" : "not normal") << ", "
     << (asymptotically_stable ? "asymptotically stable" : stable ? "stable" : "unstable") << ", |mu|max "
     << max_modulus << ", nontrivial multipliers";
  for (const auto& mu : nontrivial) os << " " << mu.real() << (mu.imag() >= 0 ? "+" : "") << mu.imag() << "i";
  return os.str();
}

namespace {
// krein_test and krein_rho (floquet.h): the nontrivial multipliers paired greedily with their reciprocals,
// rho per pair the mean of the two members' mu + 1/mu.
void KreinTest(double pair_tolerance, FloquetResult* res) {
  const std::vector<std::complex<double>>& mu = res->nontrivial;
  const int n = static_cast<int>(mu.size());
  if (n < 4 || n % 2 != 0) return;
  std::vector<bool> paired(n, false);
  std::vector<std::complex<double>> rho;
  for (int i = 0; i < n; ++i) {
    if (paired[i]) continue;
    int best = -1;
    for (int j = i + 1; j < n; ++j) {
      if (!paired[j] && (best < 0 || std::abs(mu[i] * mu[j] - 1.0) < std::abs(mu[i] * mu[best] - 1.0))) best = j;
    }
    if (best < 0 || !(std::abs(mu[i] * mu[best] - 1.0) <= pair_tolerance)) return;  // not symplectic
    paired[i] = paired[best] = true;
    rho.push_back(0.5 * (mu[i] + 1.0 / mu[i] + mu[best] + 1.0 / mu[best]));
  }
  // The product's sign (from its factors' phases: many factors would underflow) times its smallest factor's
  // modulus: continuous, zero exactly where two rho meet, of the size of the closest approach.
  std::complex<double> phase = 1.0;
  double smallest = std::numeric_limits<double>::infinity();
  for (std::size_t a = 0; a < rho.size(); ++a) {
    for (std::size_t b = a + 1; b < rho.size(); ++b) {
      const std::complex<double> factor =
          (rho[a] - rho[b]) * (rho[a] - rho[b]) / (1.0 + std::norm(rho[a]) + std::norm(rho[b]));
      const double modulus = std::abs(factor);
      if (modulus == 0.0) {
        smallest = 0.0;
        continue;
      }
      phase *= factor / modulus;
      smallest = std::min(smallest, modulus);
    }
  }
  res->krein_test = (phase.real() < 0 ? -1.0 : 1.0) * smallest;  // conjugate rho make the phase ±1
  res->krein_rho = std::move(rho);
}
}  // namespace

bool FloquetResult::HasKreinCollision(double tolerance) const {
  // The closest two rho, and whether they meet on the unit circle (|Re rho| < 2).
  for (std::size_t a = 0; a < krein_rho.size(); ++a) {
    for (std::size_t b = a + 1; b < krein_rho.size(); ++b) {
      const std::complex<double> mid = 0.5 * (krein_rho[a] + krein_rho[b]);
      if (std::abs(krein_rho[a] - krein_rho[b]) <= tolerance && std::abs(mid.real()) < 2.0) return true;
    }
  }
  return false;
}

bool FloquetResult::HasUnitComplexPair(double tolerance) const {
  return std::any_of(nontrivial.begin(), nontrivial.end(), [&](const std::complex<double>& mu) {
    return std::abs(mu.imag()) > tolerance && std::abs(std::abs(mu) - 1.0) <= tolerance;
  });
}

std::string StabilityClass::ToString() const {
  if (undetermined) {
    char text[64];
    std::snprintf(text, sizeof text, "undetermined (multipliers uncertain to %.0e)", uncertainty);
    return text;
  }
  if (asymptotically_stable) return on_level ? "asymptotically stable on its energy level" : "asymptotically stable";
  if (!unstable()) return neutrally_stable ? "neutrally stable" : "stable";
  std::string kinds;
  const auto add = [&](int count, const char* name) {
    if (count == 0) return;
    kinds += (kinds.empty() ? "" : " and ") + (count > 1 ? std::to_string(count) + " " : std::string()) + name;
  };
  add(saddle, "saddle");
  add(flip, "flip");
  add(oscillatory, "oscillatory");
  return "unstable (" + kinds + ")";
}

namespace {

// The multipliers inside the unit circle as reciprocals of B^T Phi_T^{-1} B's outside it, when both
// count the same number there (they do, but for multipliers on the circle within rounding): then
// res->nontrivial becomes the multipliers outside the circle followed by those reciprocals, and
// res->from_inverse_product is set; otherwise res is left as it is.
void TakeInsideMultipliersFromInverse(const Matrix& B, const Matrix& inverse, int reduced_dim, FloquetResult* res) {
  const Eigen::VectorXcd dual = Eigenvalues(B.transpose() * inverse * B);
  if (dual.size() == reduced_dim) {
    std::vector<std::complex<double>> outside, inside;
    for (const auto& mu : res->nontrivial) {
      if (std::abs(mu) >= 1.0) outside.push_back(mu);
    }
    for (int i = 0; i < reduced_dim; ++i) {
      const std::complex<double> nu = dual(i);
      if (std::abs(nu) > 1.0) inside.push_back(1.0 / nu);
    }
    if (outside.size() + inside.size() == static_cast<std::size_t>(reduced_dim)) {
      outside.insert(outside.end(), inside.begin(), inside.end());
      res->nontrivial = std::move(outside);
      res->from_inverse_product = true;
    }
  }
}

// Deflates the res->num_trivial trivial multipliers: with B orthonormal, spanning ker dH ∩ f^⊥, or f^⊥
// without a first integral (see the header), appends the eigenvalues of B^T Phi_T B to res->nontrivial
// (unsorted), those inside the unit circle taken from B^T Phi_T^{-1} B when a finite inverse is given.
// False, with res's status and message set, if the EigenSolver fails on B^T Phi_T B.
bool DeflateTrivialMultipliers(const Matrix& monodromy, const Vector& f0, const RowVector& dH0, bool conservative,
                               const Matrix* inverse, FloquetResult* res) {
  const int n = static_cast<int>(monodromy.rows());
  const int reduced_dim = n - res->num_trivial;
  if (reduced_dim > 0) {
    Matrix Q1 = Matrix::Identity(n, n);  // ker dH (everything without a first integral)
    if (conservative) Q1 = Matrix(Eigen::HouseholderQR<Matrix>(dH0.transpose()).householderQ()).rightCols(n - 1);
    const Vector c = Q1.transpose() * f0;
    const Matrix Qc = Eigen::HouseholderQR<Matrix>(c).householderQ();
    const Matrix B = Q1 * Qc.rightCols(reduced_dim);
    const Matrix M = B.transpose() * monodromy * B;
    const Eigen::VectorXcd reduced = Eigenvalues(M);
    if (reduced.size() != reduced_dim) {
      res->status = FloquetStatus::kEigenFailed;
      res->message = "EigenSolver failed on the deflated monodromy";
      return false;
    }
    for (int i = 0; i < reduced_dim; ++i) res->nontrivial.push_back(reduced(i));
    if (inverse != nullptr && inverse->allFinite()) TakeInsideMultipliersFromInverse(B, *inverse, reduced_dim, res);
  }
  return true;
}

// At a located branch point (FloquetOptions::at_branch_point): the cluster of nontrivial multipliers
// colliding at +1, those within branch_point_radius of it when the product of their distances to it is at
// most branch_point_product; all false otherwise.
std::vector<bool> CollidingAtBranchPoint(const std::vector<std::complex<double>>& nontrivial,
                                         const FloquetOptions& options) {
  std::vector<bool> colliding(nontrivial.size(), false);
  if (options.at_branch_point) {
    double product = 1.0;
    bool any = false;
    for (std::size_t i = 0; i < nontrivial.size(); ++i) {
      const double distance = std::abs(nontrivial[i] - 1.0);
      if (distance <= options.branch_point_radius) colliding[i] = any = true, product *= distance;
    }
    if (!any || !(product <= options.branch_point_product)) colliding.assign(colliding.size(), false);
  }
  return colliding;
}

}  // namespace

FloquetResult AnalyzeMonodromy(const Matrix& monodromy, const Vector& f0, const RowVector& dH0,
                               const FloquetOptions& options, const Matrix* inverse) {
  FloquetResult res;
  res.monodromy = monodromy;
  const int n = static_cast<int>(monodromy.rows());
  if (!monodromy.allFinite()) {
    res.status = FloquetStatus::kEigenFailed;
    res.message = "monodromy matrix has non-finite entries";
    return res;
  }
  const bool conservative = dH0.size() > 0;  // no first integral: one trivial multiplier
  res.num_trivial = conservative ? 2 : 1;
  if (!(f0.norm() > 0.0) || (conservative && !(dH0.norm() > 0.0))) {
    res.status = FloquetStatus::kDegenerateOrbit;
    res.message = "f(x0) = 0 or dH(x0) = 0 (an equilibrium): no trivial multiplier to deflate";
    return res;
  }
  res.flow_residual = (monodromy * f0 - f0).norm() / f0.norm();
  if (conservative) res.first_integral_residual = (dH0 * monodromy - dH0).norm() / dH0.norm();

  const Eigen::VectorXcd full = Eigenvalues(monodromy);
  if (full.size() != n) {
    res.status = FloquetStatus::kEigenFailed;
    res.message = "EigenSolver failed on the monodromy matrix";
    return res;
  }
  for (int i = 0; i < n; ++i) res.multipliers.push_back(full(i));
  std::sort(res.multipliers.begin(), res.multipliers.end(), [](const auto& a, const auto& b) {
    const double da = std::abs(a - 1.0), db = std::abs(b - 1.0);
    return da != db ? da < db : a.imag() > b.imag();
  });

  if (!DeflateTrivialMultipliers(monodromy, f0, dH0, conservative, inverse, &res)) return res;
  std::sort(res.nontrivial.begin(), res.nontrivial.end(), [](const auto& a, const auto& b) {
    const double ma = std::abs(a), mb = std::abs(b);
    return ma != mb ? ma > mb : a.imag() > b.imag();
  });

  // The multipliers' error (header, "Accuracy of the multipliers").
  if (!res.nontrivial.empty()) {
    res.multiplier_error = kMultiplierErrorSafety * std::max(res.flow_residual, res.first_integral_residual);
  }

  std::complex<double> bp = 1.0, pd = conservative ? 4.0 : 2.0;
  res.num_unit = res.num_trivial;
  res.max_modulus = 1.0;
  res.stable = true;
  res.asymptotically_stable = !conservative;
  const std::vector<bool> colliding = CollidingAtBranchPoint(res.nontrivial, options);
  for (std::size_t i = 0; i < res.nontrivial.size(); ++i) {
    const std::complex<double>& mu = res.nontrivial[i];
    bp *= mu - 1.0;
    pd *= mu + 1.0;
    if (colliding[i]) {  // on the unit circle, at +1
      ++res.num_unit;
      res.asymptotically_stable = false;
      continue;
    }
    if (std::abs(mu - 1.0) <= options.unit_tolerance) ++res.num_unit;
    if (std::abs(mu) > 1.0 + options.circle_tolerance) {
      res.stable = false;
      // A conjugate pair counts once (its member with the positive imaginary part).
      if (std::abs(mu.imag()) > options.circle_tolerance * std::abs(mu)) {
        if (mu.imag() > 0) ++res.stability.oscillatory;
      } else {
        ++(mu.real() > 0 ? res.stability.saddle : res.stability.flip);
      }
    }
    if (!(std::abs(mu) < 1.0 - options.circle_tolerance)) res.asymptotically_stable = false;
  }
  res.stability.on_level = conservative;
  res.stability.asymptotically_stable =
      !res.nontrivial.empty() && std::none_of(colliding.begin(), colliding.end(), [](bool c) { return c; }) &&
      std::all_of(res.nontrivial.begin(), res.nontrivial.end(),
                  [&](const std::complex<double>& mu) { return std::abs(mu) < 1.0 - options.circle_tolerance; });
  res.stability.neutrally_stable = res.stable && !res.stability.asymptotically_stable;
  if (!res.nontrivial.empty()) res.max_modulus = std::abs(res.nontrivial.front());
  std::complex<double> ns = 1.0;
  for (std::size_t i = 0; i < res.nontrivial.size(); ++i) {
    for (std::size_t j = i + 1; j < res.nontrivial.size(); ++j) ns *= res.nontrivial[i] * res.nontrivial[j] - 1.0;
  }
  res.ns_test = ns.real();
  KreinTest(options.pair_tolerance, &res);
  res.bp_test = bp.real();  // conjugate pairs make the products real up to round-off
  res.pd_test = pd.real();

  // Where the multipliers' error exceeds the tolerances, a verdict they cannot support is withheld (header,
  // "Accuracy of the multipliers").
  bool clearly_outside = false, near_circle = false;
  for (std::size_t i = 0; i < res.nontrivial.size(); ++i) {
    if (colliding[i]) continue;
    const std::complex<double>& mu = res.nontrivial[i];
    const double e = res.multiplier_error;
    if (std::abs(mu) - 1.0 > std::max(e, options.circle_tolerance)) clearly_outside = true;
    if (e > options.circle_tolerance && !(std::abs(std::abs(mu) - 1.0) > e)) near_circle = true;
  }
  if (near_circle && !clearly_outside) {
    res.stable = res.asymptotically_stable = false;
    res.stability = StabilityClass{};
    res.stability.on_level = conservative;
    res.stability.undetermined = true;
    res.stability.uncertainty = res.multiplier_error;
  }
  res.normal = res.num_unit == res.num_trivial;
  return res;
}

FloquetResult ComputeFloquet(TimeBasedShooting& shooting, const Vector& u, const FloquetOptions& options) {
  FloquetResult res;
  if (const std::string why = options.Validate(); !why.empty()) throw std::invalid_argument(why);
  Vector r;
  Matrix dr;
  if (const EvaluationStatus s = shooting.Evaluate(u, &r, &dr); !s.ok) {
    res.status = FloquetStatus::kEvaluationFailed;
    res.message = s.message;
    return res;
  }
  const HybridModel& model = shooting.model();
  const ShootingLayout& layout = shooting.layout();
  const int m = model.num_phases();
  const int k = layout.num_first_integrals();
  const Vector xi = u.segment(layout.xi_index(), k);
  Vector f_minus, f_plus, x_plus;
  Matrix D, S;
  RowVector de;
  Matrix Phi_T = Matrix::Identity(layout.dim(0), layout.dim(0));
  // Phi_T^{-1} from the inverted factors (see the header), while every factor is invertible: a factor
  // whose reciprocal condition number is below 1e-12 (a rank-deficient reset) ends it.
  Matrix inverse = Matrix::Identity(layout.dim(0), layout.dim(0));
  bool invertible = options.product_inverse;
  const auto invert_after = [&](const Matrix& factor) {  // inverse := inverse * factor^{-1}
    if (!invertible || factor.rows() != factor.cols()) {  // phases of different dimensions: no inverse
      invertible = false;
      return;
    }
    const Eigen::PartialPivLU<Matrix> lu(factor);
    if (!(lu.rcond() > 1e-12)) {
      invertible = false;
      return;
    }
    inverse = Matrix(lu.transpose().solve(Matrix(inverse.transpose()))).transpose();  // (F^{-T} inverseᵀ)ᵀ
  };
  for (int i = 0; i < m; ++i) {
    const Phase& phase = model.phase(i);
    const PhaseFlowResult& flow = shooting.segment_flow(i);
    phase.Reset(flow.x, &x_plus, &D);
    phase.Event(flow.x, &de);
    phase.UnfoldedVectorField(flow.x, xi, &f_minus, nullptr, nullptr);
    model.phase(i + 1).UnfoldedVectorField(x_plus, xi, &f_plus, nullptr, nullptr);
    if (Saltation(D, f_minus, f_plus, de, &S, options.min_transversality) != SaltationStatus::kSuccess) {
      std::ostringstream os;
      os << "segment " << i + 1 << " (phase '" << phase.name() << "', duration " << u(layout.time_index(i))
         << "): de f~^- = " << de.dot(f_minus) << " is ~0 (grazing or zero-duration transition)";
      res.status = FloquetStatus::kSaltationUndefined;
      res.message = os.str();
      return res;
    }
    res.saltations.push_back(S);
    Phi_T = S * (flow.Phi * Phi_T);
    invert_after(flow.Phi);
    invert_after(S);
  }
  Phi_T = shooting.segment_flow(m).Phi * Phi_T;
  invert_after(shooting.segment_flow(m).Phi);

  const auto x1 = u.segment(layout.state_offset(0), layout.dim(0));
  Vector f0, H;
  Matrix dH;
  model.phase(0).UnfoldedVectorField(x1, xi, &f0, nullptr, nullptr);
  model.phase(0).FirstIntegrals(x1, &H, &dH, nullptr);
  std::vector<Matrix> saltations = std::move(res.saltations);
  res = AnalyzeMonodromy(Phi_T, f0, k > 0 ? RowVector(dH.row(0)) : RowVector(), options,
                         invertible ? &inverse : nullptr);
  res.saltations = std::move(saltations);
  return res;
}

Eigen::VectorXcd Eigenvalues(const Matrix& a) {
  const Eigen::EigenSolver<Matrix> solver(a, /*computeEigenvectors=*/false);
  if (solver.info() != Eigen::Success) return Eigen::VectorXcd();
  return solver.eigenvalues();
}

}  // namespace hybridcont
