// Momentum and energy exchange of both couplings (typed over the coupling list): a tilted
// patch moves obliquely through still air in a periodic box (no boundary forces); the air's
// momentum change equals minus the structure's, to round-off, every step, with and without
// structure substeps. Penalty: the structure's momentum change equals the coupling impulse
// every step and the air's energy change equals the coupling work Σ W given to it.
// Embedded: the structure's momentum change equals the coupling impulse to 1e-12 over more
// than ten patched faces.
#include <doctest/doctest.h>

#include <parafsi/model/fabric_catalogue.hpp>

#include <cmath>
#include <cstdio>
#include <string>

#include "coupling_test_util.hpp"

namespace pf = parafsi;

namespace {

/// What differs per coupling: the still air, PFAC, and the extra per-step checks.
template <class C>
struct balance;

template <>
struct balance<ctu::penalty> {
  static constexpr double rho = 1.18;  // the solver's ambient state
  static constexpr double pfac_impermeable = 0.1, pfac_porous = 1.0;
  struct extra {
    double worst_e = 0;
    long max_m = 0;
  };
  template <class S>
  static void each_step(extra& x, const S& s, const Eigen::Vector3d& dps, const Eigen::Vector3d& ps0, double de,
                        double e0) {
    const auto& d = s.coupling().diagnostics();
    // Structure momentum change = coupling impulse (no other load).
    CHECK((dps - d.impulse_structure).norm() <= 1e-12 * (ps0.norm() + d.impulse_structure.norm()));
    x.worst_e = std::max(x.worst_e, std::fabs(de - d.work_fluid) / e0);  // round-off of the energy sum
    x.max_m = std::max(x.max_m, s.last_substeps());
  }
  static void finish(const extra& x) {
    std::printf("  max substeps %ld, max |dE_fluid - W| / E_fluid = %.2e\n", x.max_m, x.worst_e);
    CHECK(x.worst_e < 1e-13);
  }
  template <class S>
  static void impermeable_extra(const S& s) {
    CHECK(s.coupling().points().size() > 0);
    CHECK(s.coupling().diagnostics().max_penetration_over_h > 0);
  }
};

template <bool OS>
struct balance<ctu::embedded_t<OS>> {
  static constexpr double rho = 1.2;
  static constexpr double pfac_impermeable = 0, pfac_porous = 0;
  struct extra {
    pf::index_t faces = 0;
    double worst_s = 0;
  };
  template <class S>
  static void each_step(extra& x, const S& s, const Eigen::Vector3d& dps, const Eigen::Vector3d&, double, double) {
    const auto& d = s.coupling().diagnostics();
    x.faces = std::max(x.faces, d.faces);
    x.worst_s = std::max(x.worst_s, (dps - d.impulse_structure).norm() / std::max(d.impulse_structure.norm(), 1e-300));
  }
  static void finish(const extra& x) {
    std::printf("  up to %ld patched faces, max |dP_structure - J| / |J| = %.2e\n", long(x.faces), x.worst_s);
    CHECK(x.faces > 10);
    CHECK(x.worst_s < 1e-12);
  }
  template <class S>
  static void impermeable_extra(const S&) {}
};

template <class C, class S>
void check_balance(S& s, int steps, const std::string& label) {
  auto fm = [&] {
    const auto t = s.fluid().totals();
    return Eigen::Vector3d(t.momentum[0], t.momentum[1], t.momentum[2]);
  };
  typename balance<C>::extra x;
  double worst = 0, scale = 0;
  for (int n = 0; n < steps; ++n) {
    const Eigen::Vector3d pf0 = fm(), ps0 = s.structure().linear_momentum();
    const double e0 = s.fluid().totals().energy;
    s.step(s.stable_dt(0.5));
    const Eigen::Vector3d dpf = fm() - pf0, dps = s.structure().linear_momentum() - ps0;
    const auto& d = s.coupling().diagnostics();
    scale = std::max(scale, d.impulse_structure.norm());
    worst = std::max(worst, (dpf + dps).norm() / std::max(d.impulse_structure.norm(), 1e-300));
    balance<C>::each_step(x, s, dps, ps0, s.fluid().totals().energy - e0, e0);
  }
  std::printf("%s %s: %d steps, max step impulse %.3e N s, max |dP_fluid + dP_structure| / |J| = %.2e\n", C::name,
              label.c_str(), steps, scale, worst);
  balance<C>::finish(x);
  CHECK(scale > 0);
  CHECK(worst < 1e-9);
}

}  // namespace

TEST_CASE_TEMPLATE_DEFINE("impulse balance to round-off every step (impermeable, moving membrane)", C, impermeable) {
  using B = balance<C>;
  pf::parallel::set_threads(1);
  auto s = ctu::tilted_patch(C::make(pf::porosity::impermeable{}, B::pfac_impermeable), B::rho, 0.5, 1e5);
  check_balance<C>(s, 40, "impermeable");
  B::impermeable_extra(s);
}
TEST_CASE_TEMPLATE_APPLY(impermeable, ctu::couplings);

TEST_CASE_TEMPLATE_DEFINE("impulse balance with structure substeps and a porous fabric", C, porous) {
  using B = balance<C>;
  const auto& f = pf::model::fabric_catalogue[2];
  auto s = ctu::tilted_patch(C::make(pf::porosity::ergun{f.alpha, f.beta, f.thickness}, B::pfac_porous), B::rho, 0.05,
                             5e10);
  check_balance<C>(s, 40, "ergun mat509, stiff membrane");
  CHECK(s.last_substeps() > 1);
}
TEST_CASE_TEMPLATE_APPLY(porous, ctu::couplings);
