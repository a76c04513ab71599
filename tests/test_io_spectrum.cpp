// io::dominant_frequency on synthetic records with known answers: a tone on uneven
// samples (frequency to a small fraction of 1/T, amplitude within the Hann scalloping),
// two signals in quadrature (a rotating side force), a tone under noise, and bad input.
#include <doctest/doctest.h>

#include "approx.hpp"

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <parafsi/io/spectrum.hpp>

using namespace parafsi;

namespace {
// Uneven times: steps of 1 ms ± 30 %, as a solver's adaptive steps, over [t0, t0 + T].
std::vector<double> uneven_times(double t0, double T, unsigned seed) {
  std::mt19937 g(seed);
  std::uniform_real_distribution<double> u(0.7e-3, 1.3e-3);
  std::vector<double> t{t0};
  while (t.back() < t0 + T) t.push_back(t.back() + u(g));
  return t;
}
}  // namespace

TEST_CASE("dominant_frequency: a tone on uneven samples, frequency to 1e-3/T, amplitude to 2 %") {
  const double T = 2.0;
  for (double f : {3.3, 7.77, 25.1}) {
    const auto t = uneven_times(0.4, T, 7);
    std::vector<double> x(t.size());
    for (std::size_t i = 0; i < t.size(); ++i) x[i] = 0.8 + 0.05 * std::sin(2 * std::numbers::pi * f * t[i] + 0.3);
    const auto pk = io::dominant_frequency(t, {x}, 0.5, 100.0);
    CAPTURE(f);
    CHECK(std::abs(pk.frequency - f) < 1e-3 / T * f);  // ≪ the bin 1/T = 0.5 Hz
    CHECK(pk.amplitude == pft::rel(0.05, 0.02));
    CHECK(pk.periods == doctest::Approx(f * (t.back() - t.front())).epsilon(1e-3));
    CHECK(pk.power_fraction > 0.99);
  }
}

TEST_CASE("dominant_frequency: two signals in quadrature (a rotating side force) sum their power") {
  const auto t = uneven_times(0.0, 3.0, 11);
  const double f = 4.2;
  std::vector<double> y(t.size()), z(t.size());
  for (std::size_t i = 0; i < t.size(); ++i) {
    y[i] = 0.03 * std::cos(2 * std::numbers::pi * f * t[i]);
    z[i] = 0.03 * std::sin(2 * std::numbers::pi * f * t[i]);
  }
  const auto pk = io::dominant_frequency(t, {y, z}, 0.5, 50.0);
  CHECK(std::abs(pk.frequency - f) < 1e-3);
  CHECK(pk.amplitude == pft::rel(0.03 * std::sqrt(2.0), 0.02));
}

TEST_CASE("dominant_frequency: a weak tone under noise is found; noise alone has no dominant lobe") {
  const auto t = uneven_times(0.0, 4.0, 3);
  std::mt19937 g(5);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<double> x(t.size()), noise(t.size());
  for (std::size_t i = 0; i < t.size(); ++i) {
    noise[i] = n(g);
    x[i] = 0.5 * std::sin(2 * std::numbers::pi * 9.0 * t[i]) + noise[i];
  }
  const auto pk = io::dominant_frequency(t, {x}, 1.0, 100.0);
  CHECK(std::abs(pk.frequency - 9.0) < 0.05);
  CHECK(pk.amplitude == pft::rel(0.5, 0.25));
  const auto pn = io::dominant_frequency(t, {noise}, 1.0, 100.0);
  CHECK(pn.power_fraction < 0.1);  // a lobe of 4/T out of a 99 Hz band of white noise: ≈ 0.01
}

TEST_CASE("dominant_frequency: bad input is refused with a message") {
  std::vector<double> t{0, 1, 2, 3, 4, 5, 6, 7}, x(8, 1.0), shortx(7, 1.0);
  CHECK_THROWS_WITH(io::dominant_frequency(std::vector<double>{0, 1}, {std::vector<double>{1, 2}}, 0.1, 1.0),
                    doctest::Contains("at least 8 samples"));
  CHECK_THROWS_WITH(io::dominant_frequency(t, {shortx}, 0.01, 0.5), doctest::Contains("a signal has 7 samples"));
  CHECK_THROWS_WITH(io::dominant_frequency(t, {x}, 0.5, 0.1), doctest::Contains("bad band"));
  t[3] = 2;
  CHECK_THROWS_WITH(io::dominant_frequency(t, {x}, 0.01, 0.5), doctest::Contains("times must increase"));
}
