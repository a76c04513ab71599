// Core utilities: type lists, SoA containers, SIMD helpers, aligned storage,
// deterministic parallel reductions, policy composition helpers.
#include <doctest/doctest.h>

#include "approx.hpp"

#include <numeric>
#include <parafsi/parafsi.hpp>

using namespace parafsi;

namespace {
struct a_tag {};
struct b_tag {};
struct c_tag {};
using L1 = meta::list<a_tag, b_tag>;
using L2 = meta::list<b_tag, c_tag>;
static_assert(meta::contains_v<a_tag, L1> && !meta::contains_v<c_tag, L1>);
static_assert(meta::index_of_v<b_tag, L1> == 1);
static_assert(std::is_same_v<meta::union_t<L1, L2>, meta::list<a_tag, b_tag, c_tag>>);
static_assert(std::is_same_v<meta::union_t<L1, L2, L1>, meta::list<a_tag, b_tag, c_tag>>);
static_assert(soa<a_tag, b_tag>::has<a_tag>() && !soa<a_tag, b_tag>::has<c_tag>());
static_assert(std::is_same_v<soa_of_t<L2>, soa<b_tag, c_tag>>);
static_assert(std::is_same_v<pick_t<kind::flux, int, flux::rusanov, gas::ideal>, flux::rusanov>);
static_assert(std::is_same_v<pick_t<kind::flux, flux::hllc, gas::ideal>, flux::hllc>);
static_assert(count_kind_v<kind::flux, flux::rusanov, flux::hllc, gas::ideal> == 2);
}  // namespace

TEST_CASE("soa: named fields, 64-byte alignment, padded tails") {
  soa<a_tag, b_tag> s(13, 2.5);
  CHECK(s.size() == 13);
  CHECK(reinterpret_cast<std::uintptr_t>(s.get<a_tag>()) % 64 == 0);
  CHECK(reinterpret_cast<std::uintptr_t>(s.get<b_tag>()) % 64 == 0);
  // The padding past the end is filled, so a full-pack load at the last element is finite.
  CHECK(simd::all_finite(simd::load<simd::pack<double>>(s.get<a_tag>() + 12)));
  s.get<b_tag>()[3] = 7.0;
  CHECK(s.span<b_tag>()[3] == 7.0);
  CHECK(s.span<a_tag>().size() == 13);
}

TEST_CASE("paged_soa: zero when made, 64-byte aligned, the padded length of soa, moves keep the data") {
  // Large enough that the C library maps fresh pages (the lazily backed case) and small.
  for (index_t n : {index_t(13), index_t(3'000'000)}) {
    paged_soa<a_tag, b_tag> s(n);
    CHECK(s.size() == n);
    for (std::size_t f = 0; f < 2; ++f) CHECK(reinterpret_cast<std::uintptr_t>(s.data(f)) % 64 == 0);
    const std::size_t len = simd::padded(std::size_t(n)) + simd::width;  // as soa allocates
    double sum = 0.0;
    for (std::size_t i = 0; i < len; ++i) sum += std::fabs(s.get<a_tag>()[i]) + std::fabs(s.get<b_tag>()[i]);
    CHECK(sum == 0.0);
    s.get<b_tag>()[len - 1] = 4.0;
    s.get<a_tag>()[n / 2] = -1.5;
    const double* before = s.data(1);
    paged_soa<a_tag, b_tag> t(std::move(s));
    CHECK(t.data(1) == before);
    CHECK(t.get<b_tag>()[len - 1] == 4.0);
    CHECK(t.get<a_tag>()[n / 2] == -1.5);
    paged_soa<a_tag, b_tag> u;
    u = std::move(t);
    CHECK(u.get<a_tag>()[n / 2] == -1.5);
    CHECK(u.size() == n);
  }
}

TEST_CASE("for_each_pack covers [begin, end) once: packs, then the scalar tail") {
  for (index_t n : {0, 1, 7, 8, 9, 31, 64, 65}) {
    std::vector<int> hits(std::size_t(n) + 3, 0);
    int packs = 0, scalars = 0;
    simd::for_each_pack(2, n + 2, [&](auto tag, index_t i) {
      using V = typename decltype(tag)::type;
      if constexpr (simd::is_pack_v<V>) {
        ++packs;
        for (std::size_t l = 0; l < simd::width; ++l) ++hits[std::size_t(i) + l];
      } else {
        ++scalars;
        ++hits[std::size_t(i)];
      }
    });
    CHECK(packs == int(n / index_t(simd::width)));
    CHECK(scalars == int(n % index_t(simd::width)));
    for (index_t i = 0; i < n + 3; ++i) CHECK(hits[std::size_t(i)] == ((i >= 2 && i < n + 2) ? 1 : 0));
  }
}

TEST_CASE("SIMD math helpers match the scalar ones lane by lane") {
  using P = simd::pack<double>;
  alignas(64) double a[simd::width], b[simd::width], o[simd::width];
  for (std::size_t l = 0; l < simd::width; ++l) {
    a[l] = -1.5 + 0.7 * double(l);
    b[l] = 0.3 - 0.2 * double(l);
  }
  const P pa = P::load_aligned(a), pb = P::load_aligned(b);
  auto check = [&](P r, auto f) {
    r.store_aligned(o);
    for (std::size_t l = 0; l < simd::width; ++l) CHECK(o[l] == doctest::Approx(f(a[l], b[l])).epsilon(1e-15));
  };
  check(simd::min(pa, pb), [](double x, double y) { return simd::min(x, y); });
  check(simd::max(pa, pb), [](double x, double y) { return simd::max(x, y); });
  check(simd::abs(pa), [](double x, double) { return std::fabs(x); });
  check(simd::sqrt(simd::abs(pa)), [](double x, double) { return std::sqrt(std::fabs(x)); });
  check(simd::select(pa > pb, pa, pb), [](double x, double y) { return x > y ? x : y; });
  check(simd::copysign(pa, pb), [](double x, double y) { return std::copysign(x, y); });
  double sum = 0;
  for (std::size_t l = 0; l < simd::width; ++l) sum += a[l];
  CHECK(simd::hsum(pa) == doctest::Approx(sum).epsilon(1e-15));
  CHECK(simd::hmax(pa) == doctest::Approx(a[simd::width - 1]));
  CHECK(simd::iota<P>().get(simd::width - 1) == double(simd::width - 1));
}

TEST_CASE("parallel::reduce is independent of the thread count") {
  std::vector<double> x(10007);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = 1.0 / double(i + 1) * ((i % 3) ? 1.0 : -1e-3);
  const int t0 = parallel::max_threads();
  auto run = [&](int t) {
    parallel::set_threads(t);
    return parallel::reduce(
        index_t(0), index_t(x.size()), 0.0, [&](index_t i) { return x[std::size_t(i)]; },
        [](double a, double b) { return a + b; });
  };
  const double r1 = run(1), r2 = run(2);
  parallel::set_threads(t0);
  CHECK(r1 == r2);  // bit for bit
  CHECK(r1 == doctest::Approx(std::accumulate(x.begin(), x.end(), 0.0)).epsilon(1e-14));
}

TEST_CASE("require throws invalid_input with the concatenated message") {
  try {
    require(false, "value ", 3.5, " out of range");
    FAIL("no throw");
  } catch (const invalid_input& e) {
    CHECK(std::string(e.what()) == "value 3.5 out of range");
  }
}

TEST_CASE("tests' pft::rel is relative at every size, where doctest::Approx is absolute below 1") {
  // doctest's scale of 1: 5 % off 0.078 passes "to 2 %", twice 5e-15 passes "to 1e-9".
  CHECK(0.078 * 1.05 == doctest::Approx(0.078).epsilon(0.02));
  CHECK(1e-14 == doctest::Approx(5e-15).epsilon(1e-9));
  CHECK(0.078 * 1.05 != pft::rel(0.078, 0.02));
  CHECK(0.078 * 1.019 == pft::rel(0.078, 0.02));
  CHECK(1e-14 != pft::rel(5e-15, 1e-9));
  CHECK(5e-15 * (1 + 1e-10) == pft::rel(5e-15, 1e-9));
  CHECK(-3e7 * (1 + 1e-10) == pft::rel(-3e7, 1e-9));
  CHECK(-3e7 * (1 + 1e-8) != pft::rel(-3e7, 1e-9));
  CHECK(2e-290 * (1 + 1e-8) != pft::rel(2e-290, 1e-9));
  CHECK(0.0 == pft::rel(0.0, 1e-17));
  CHECK(0.0 == pft::rel(0.0, 1e-12));
  CHECK(1e-300 != pft::rel(0.0, 1e-12));
}
