// Pointwise flux properties: consistency, HLLC-LM(φ = 1) ≡ HLLC, scalar ≡ SIMD
// for every flux and limiter, the ALE shift equals F·n − w_n U for equal states.
#include <doctest/doctest.h>

#include "approx.hpp"

#include <random>

#include "fluid_test_util.hpp"

using namespace parafsi;
using fluid::cons;
using fluid::prim;

namespace {
struct sample {
  prim<double> L, R;
  vec3<double> n;
};
std::vector<sample> random_samples(int n, double mach_scale, unsigned seed = 7) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(-1.0, 1.0), P(0.2, 3.0);
  std::vector<sample> out;
  for (int i = 0; i < n; ++i) {
    sample s;
    s.L = {P(rng), {mach_scale * U(rng), mach_scale * U(rng), mach_scale * U(rng)}, P(rng)};
    s.R = {P(rng), {mach_scale * U(rng), mach_scale * U(rng), mach_scale * U(rng)}, P(rng)};
    Eigen::Vector3d v(U(rng), U(rng), U(rng));
    v.normalize();
    s.n = {v[0], v[1], v[2]};
    out.push_back(s);
  }
  return out;
}
double rel(const cons<double>& a, const cons<double>& b) {
  const double scale = 1.0 + std::fabs(a.rho) + std::fabs(a.E) + std::fabs(a.m.x) + std::fabs(a.m.y) + std::fabs(a.m.z);
  const double d = std::fabs(a.rho - b.rho) + std::fabs(a.m.x - b.m.x) + std::fabs(a.m.y - b.m.y) +
                   std::fabs(a.m.z - b.m.z) + std::fabs(a.E - b.E);
  return d / scale;
}
}  // namespace

TEST_CASE_TEMPLATE("flux is consistent: F(W, W) equals the physical flux", Flux, flux::hllc_lm, flux::hllc,
                   flux::rusanov, flux::ausm_plus_up) {
  const gas::ideal g{};
  const Flux f{};
  double worst = 0;
  for (const auto& s : random_samples(500, 1.5)) {
    const double un = dot(s.L.u, s.n);
    const double E = g.total_energy(s.L.rho, s.L.u.x, s.L.u.y, s.L.u.z, s.L.p);
    worst = std::max(worst, rel(f(s.L, s.L, s.n, g), fluid::physical_flux(s.L, E, un, s.n)));
  }
  MESSAGE(Flux::name(), ": max relative deviation from the physical flux = ", worst);
  CHECK(worst < 1e-13);
}

TEST_CASE("HLLC-LM with phi = 1 equals HLLC to round-off") {
  const gas::ideal g{};
  const flux::hllc_lm lm{1e-300};  // M_loc / M_lim >= 1 everywhere: φ = sin(π/2) = 1
  const flux::hllc h{};
  double worst = 0;
  for (double ms : {0.01, 0.3, 2.0})
    for (const auto& s : random_samples(2000, ms))
      worst = std::max(worst, rel(lm(s.L, s.R, s.n, g), h(s.L, s.R, s.n, g)));
  MESSAGE("max relative difference HLLC-LM(phi=1) vs HLLC = ", worst);
  CHECK(worst < 1e-13);
}

TEST_CASE("HLLC-LM reduces the dissipation of vortical low-Mach jumps, not of acoustic ones") {
  const gas::ideal g{};
  const vec3<double> n{1, 0, 0};
  auto central_mx = [&](const prim<double>& L, const prim<double>& R) {
    return 0.5 * (L.rho * L.u.x * L.u.x + L.p + R.rho * R.u.x * R.u.x + R.p);
  };
  // Converging low-Mach flow without a pressure jump (sensor r = 0): φ = sin(π/2 M/M_lim).
  const prim<double> L{1.0, {0.01, 0.02, 0}, 1.0}, R{1.0, {-0.01, -0.02, 0}, 1.0};
  const double d_hllc = std::fabs(flux::hllc{}(L, R, n, g).m.x - central_mx(L, R));
  const double d_lm = std::fabs(flux::hllc_lm{}(L, R, n, g).m.x - central_mx(L, R));
  MESSAGE("normal-momentum dissipation across a low-Mach velocity jump: hllc ", d_hllc, ", hllc_lm ", d_lm);
  CHECK(d_lm < 0.25 * d_hllc);
  // An acoustic simple wave (Δp ≥ ρ c Δu: sensor r = 1): HLLC-LM equals HLLC.
  const double c = std::sqrt(1.4), du = 1e-4;
  const prim<double> A{1.0, {du, 0, 0}, 1.0 + 1.01 * c * du}, B{1.0, {0, 0, 0}, 1.0};
  const auto Flm = flux::hllc_lm{}(A, B, n, g), Fh = flux::hllc{}(A, B, n, g);
  CHECK(Flm.rho == pft::rel(Fh.rho, 1e-10));  // equal in exact arithmetic; ~1e-12 apart in doubles
  CHECK(Flm.m.x == pft::rel(Fh.m.x, 1e-12));
  // The paper's form (no floor) keeps the acoustic dissipation low as well.
  const auto Fpaper = flux::hllc_lm{0.1, 0.0}(A, B, n, g);
  CHECK(std::fabs(Fpaper.rho - 0.5 * (A.rho * du)) < 0.1 * std::fabs(Fh.rho - 0.5 * (A.rho * du)));
}

TEST_CASE_TEMPLATE("scalar and SIMD instantiations of every flux give the same numbers", Flux, flux::hllc_lm,
                   flux::hllc, flux::rusanov, flux::ausm_plus_up) {
  using P = simd::pack<double>;
  constexpr std::size_t W = simd::width;
  const gas::ideal g{};
  const Flux f{};
  auto samples = random_samples(int(W) * 64, 0.8, 11);
  const vec3<double> n{0.6, 0.0, 0.8};
  double worst = 0;
  for (std::size_t b = 0; b < samples.size(); b += W) {
    alignas(64) double a[10][W];
    for (std::size_t l = 0; l < W; ++l) {
      const auto& s = samples[b + l];
      const double v[10] = {s.L.rho, s.L.u.x, s.L.u.y, s.L.u.z, s.L.p, s.R.rho, s.R.u.x, s.R.u.y, s.R.u.z, s.R.p};
      for (int q = 0; q < 10; ++q) a[q][l] = v[q];
    }
    auto ld = [&](int q) { return P::load_aligned(a[q]); };
    const prim<P> L{ld(0), {ld(1), ld(2), ld(3)}, ld(4)}, R{ld(5), {ld(6), ld(7), ld(8)}, ld(9)};
    const cons<P> F = f(L, R, n, g);
    alignas(64) double out[5][W];
    F.rho.store_aligned(out[0]);
    F.m.x.store_aligned(out[1]);
    F.m.y.store_aligned(out[2]);
    F.m.z.store_aligned(out[3]);
    F.E.store_aligned(out[4]);
    for (std::size_t l = 0; l < W; ++l) {
      const auto& s = samples[b + l];
      const cons<double> Fs = f(s.L, s.R, n, g);
      const cons<double> Fv{out[0][l], {out[1][l], out[2][l], out[3][l]}, out[4][l]};
      worst = std::max(worst, rel(Fs, Fv));
    }
  }
  MESSAGE(Flux::name(), ": max relative scalar/SIMD difference = ", worst);
  CHECK(worst < 1e-14);
}

TEST_CASE_TEMPLATE("scalar and SIMD limiters agree and are TVD-bounded", Lim, limiter::van_leer, limiter::minmod,
                   limiter::mc) {
  using P = simd::pack<double>;
  constexpr std::size_t W = simd::width;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> U(-2.0, 2.0);
  const Lim lim{};
  for (int rep = 0; rep < 200; ++rep) {
    alignas(64) double a[W], b[W], o[W];
    for (std::size_t l = 0; l < W; ++l) {
      a[l] = U(rng);
      b[l] = (l % 3 == 0) ? -a[l] : U(rng);  // include a + b = 0
    }
    lim(P::load_aligned(a), P::load_aligned(b)).store_aligned(o);
    for (std::size_t l = 0; l < W; ++l) {
      const double s = lim(a[l], b[l]);
      REQUIRE(s == doctest::Approx(o[l]).epsilon(1e-15));
      // TVD: |slope| ≤ 2 min(|a|, |b|), zero at extrema, same sign as a and b.
      CHECK(std::fabs(s) <= 2.0 * std::min(std::fabs(a[l]), std::fabs(b[l])) + 1e-15);
      if (a[l] * b[l] <= 0) CHECK(s == 0.0);
    }
  }
}

TEST_CASE("ALE shift: equal states give F(U)·n − w_n U exactly (Galilean shift)") {
  const gas::ideal g{};
  for (const auto& s : random_samples(200, 0.5, 5)) {
    const double wn = 0.37;
    const auto G = flux::ale_flux(flux::hllc{}, s.L, s.L, s.n, wn, g);
    const double un = dot(s.L.u, s.n);
    const double E = g.total_energy(s.L.rho, s.L.u.x, s.L.u.y, s.L.u.z, s.L.p);
    const auto F = fluid::physical_flux(s.L, E, un, s.n);
    const cons<double> U{s.L.rho, s.L.u * s.L.rho, E};
    CHECK(rel(G, F - U * wn) < 1e-13);
  }
}
